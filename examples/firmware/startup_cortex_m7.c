/* Vector table and reset handler for a Cortex-M7 (any vendor): what runs before main.
 *
 * Reset: enable the FPU, copy .data from flash, zero .bss, point VTOR at this table, run static
 * constructors, call main. Symbols come from the linker script (stm32f767xg.ld).
 * The table holds the 16 core exceptions only: the example enables no device interrupt (the
 * NVIC starts with all of them disabled); a firmware that does appends its part's IRQ vectors. */
#include <stdint.h>

#include "board.h"

typedef void (*vector_t)(void);

/* Linker script symbols: addresses only, never read as objects. */
extern uint32_t __stack_top__;
extern uint32_t __data_start__;
extern uint32_t __data_end__;
extern const uint32_t __data_load__;
extern uint32_t __bss_start__;
extern uint32_t __bss_end__;
extern vector_t __preinit_array_start[];
extern vector_t __preinit_array_end[];
extern vector_t __init_array_start[];
extern vector_t __init_array_end[];

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void Fault_Handler(void);

/* Faults (HardFault, MemManage, BusFault, UsageFault, NMI): the safe state. */
void Fault_Handler(void) { board_fail_safe(); }

/* Any exception the firmware does not handle is a bug: the safe state as well. */
void Default_Handler(void) { board_fail_safe(); }

void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));

/* System control block. */
#define SCB_VTOR (*(volatile uint32_t*)0xE000ED08U)
#define SCB_CPACR (*(volatile uint32_t*)0xE000ED88U)
#define CPACR_CP10_CP11_FULL (0xFU << 20)

typedef struct vector_table_s {
  uint32_t* initial_stack;
  vector_t handlers[15];
} vector_table_t;

__attribute__((section(".isr_vector"), used)) const vector_table_t g_vector_table = {
    &__stack_top__,
    {
        Reset_Handler,    /* 1 reset */
        Fault_Handler,    /* 2 NMI */
        Fault_Handler,    /* 3 HardFault */
        Fault_Handler,    /* 4 MemManage */
        Fault_Handler,    /* 5 BusFault */
        Fault_Handler,    /* 6 UsageFault */
        0, 0, 0, 0,       /* 7-10 reserved */
        SVC_Handler,      /* 11 */
        DebugMon_Handler, /* 12 */
        0,                /* 13 reserved */
        PendSV_Handler,   /* 14 */
        SysTick_Handler,  /* 15 */
    },
};

void Reset_Handler(void) {
  /* The FPU first: compiled for -mfloat-abi=hard, any later code may use FPU registers, and
   * an FPU instruction with CP10/CP11 disabled is a UsageFault. */
  SCB_CPACR |= CPACR_CP10_CP11_FULL;
  __asm volatile("dsb\n\tisb" ::: "memory");

  const uint32_t* source = &__data_load__;
  for (uint32_t* word = &__data_start__; word < &__data_end__; ++word) {
    *word = *source++;
  }
  for (uint32_t* word = &__bss_start__; word < &__bss_end__; ++word) {
    *word = 0U;
  }
  SCB_VTOR = (uint32_t)(uintptr_t)&g_vector_table;
  __asm volatile("dsb\n\tisb" ::: "memory");

  for (vector_t* ctor = __preinit_array_start; ctor < __preinit_array_end; ++ctor) {
    (*ctor)();
  }
  for (vector_t* ctor = __init_array_start; ctor < __init_array_end; ++ctor) {
    (*ctor)();
  }
  (void)main();
  board_fail_safe(); /* main never returns; if it did, nothing may keep running */
}
