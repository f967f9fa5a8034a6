/* board.h for an STM32F767 (Nucleo-F767ZI wiring: USART3 on PD8/PD9 is the ST-LINK virtual COM
 * port). Register addresses and bits from RM0410 and the Cortex-M7 generic user guide.
 *
 * The core runs on its reset clock, the 16 MHz HSI: enough to show the loop; a product sets up
 * the PLL (216 MHz) and flash wait states first, and enables the M7's caches. */
#include "board.h"

#define REG32(address) (*(volatile uint32_t*)(address))

/* SysTick (Cortex-M7 system control space). */
#define SYST_CSR REG32(0xE000E010U)
#define SYST_RVR REG32(0xE000E014U)
#define SYST_CVR REG32(0xE000E018U)
#define SYST_CSR_ENABLE (1U << 0)
#define SYST_CSR_TICKINT (1U << 1)
#define SYST_CSR_CLKSOURCE_CPU (1U << 2)

/* Reset and clock control, GPIO port D, USART3. */
#define RCC_AHB1ENR REG32(0x40023830U)
#define RCC_APB1ENR REG32(0x40023840U)
#define RCC_AHB1ENR_GPIODEN (1U << 3)
#define RCC_APB1ENR_USART3EN (1U << 18)
#define GPIOD_MODER REG32(0x40020C00U)
#define GPIOD_AFRH REG32(0x40020C24U)
#define USART3_CR1 REG32(0x40004800U)
#define USART3_BRR REG32(0x4000480CU)
#define USART3_ISR REG32(0x4000481CU)
#define USART3_TDR REG32(0x40004828U)
#define USART_CR1_UE (1U << 0)
#define USART_CR1_TE (1U << 3)
#define USART_ISR_TXE (1U << 7)

#define CORE_CLOCK_HZ 16000000U /* HSI after reset; APB1 runs at the same clock */
#define UART_BAUD 115200U
#define UART_BUFFER_BYTES 2048U /* a power of two: the free-running ring counters wrap cleanly */

static volatile uint64_t g_ticks;
static board_tick_handler_t g_on_tick;

/* Transmit ring, main loop only: free-running counters, head advanced by board_uart_queue, tail
 * by board_uart_poll. */
static uint8_t g_tx[UART_BUFFER_BYTES];
static uint32_t g_tx_head;
static uint32_t g_tx_tail;

void SysTick_Handler(void);
void SysTick_Handler(void) {
  const uint64_t tick = g_ticks + 1U;
  g_ticks = tick;
  if (g_on_tick != NULL) {
    g_on_tick(tick);
  }
}

static void uart_init(void) {
  RCC_AHB1ENR |= RCC_AHB1ENR_GPIODEN;
  RCC_APB1ENR |= RCC_APB1ENR_USART3EN;
  (void)RCC_APB1ENR; /* read back: the clock is running before the peripheral is touched */
  /* PD8 (TX) and PD9 (RX): alternate function 7. */
  GPIOD_MODER = (GPIOD_MODER & ~(0xFU << 16)) | (0xAU << 16);
  GPIOD_AFRH = (GPIOD_AFRH & ~0xFFU) | 0x77U;
  /* 8N1, oversampling by 16: BRR = f_APB1 / baud, rounded. */
  USART3_BRR = (CORE_CLOCK_HZ + UART_BAUD / 2U) / UART_BAUD;
  USART3_CR1 = USART_CR1_TE | USART_CR1_UE;
}

void board_init(board_tick_handler_t on_tick) {
  uart_init();
  g_ticks = 0U;
  g_on_tick = on_tick;
  SYST_RVR = CORE_CLOCK_HZ / (1000000U / BOARD_TICK_US) - 1U;
  SYST_CVR = 0U;
  SYST_CSR = SYST_CSR_CLKSOURCE_CPU | SYST_CSR_TICKINT | SYST_CSR_ENABLE;
}

uint32_t board_lock(void) {
  uint32_t primask;
  __asm volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask)::"memory");
  return primask;
}

void board_unlock(uint32_t previous) { __asm volatile("msr primask, %0" ::"r"(previous) : "memory"); }

uint64_t board_ticks(void) {
  /* A 64-bit read is two loads: keep the tick interrupt out between them. */
  const uint32_t previous = board_lock();
  const uint64_t ticks = g_ticks;
  board_unlock(previous);
  return ticks;
}

size_t board_uart_room(void) { return UART_BUFFER_BYTES - (g_tx_head - g_tx_tail); }

bool board_uart_queue(const uint8_t* data, size_t size) {
  if (data == NULL || size > board_uart_room()) {
    return false;
  }
  for (size_t i = 0; i < size; ++i) {
    g_tx[(g_tx_head + (uint32_t)i) % UART_BUFFER_BYTES] = data[i];
  }
  g_tx_head += (uint32_t)size;
  return true;
}

void board_uart_poll(void) {
  while (g_tx_tail != g_tx_head && (USART3_ISR & USART_ISR_TXE) != 0U) {
    USART3_TDR = g_tx[g_tx_tail % UART_BUFFER_BYTES];
    ++g_tx_tail;
  }
}

void board_fail_safe(void) {
  __asm volatile("cpsid i" ::: "memory");
  for (;;) {
  }
}
