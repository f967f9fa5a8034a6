/* The few board services the example firmware needs: a 1 kHz tick interrupt, a UART that sends
 * telemetry, a way to keep the tick out of a critical section, and the safe state.
 * board_stm32f7.c implements them for an STM32F767 (registers from RM0410); porting the example
 * to another part means rewriting that one file.
 *
 * Everything here is non-blocking and allocation-free.
 */
#ifndef PLIANT_EXAMPLE_BOARD_H
#define PLIANT_EXAMPLE_BOARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/** Period of the control tick, microseconds (1 kHz). */
#define BOARD_TICK_US 1000U

/** Called from the tick interrupt with the new tick count. */
typedef void (*board_tick_handler_t)(uint64_t tick);

/** Starts the telemetry UART, then the tick interrupt, which calls `on_tick` every
 *  BOARD_TICK_US from then on. The core keeps its reset clock. */
void board_init(board_tick_handler_t on_tick);

/** Ticks since board_init (monotonic; 64 bits do not wrap in the life of a machine). */
uint64_t board_ticks(void);

/** Keeps the tick interrupt out until board_unlock(the returned value); nests. Keep it short:
 *  the control cycle waits meanwhile. */
uint32_t board_lock(void);
void board_unlock(uint32_t previous);

/** Bytes board_uart_queue accepts now. Main loop only. */
size_t board_uart_room(void);

/** Queues `size` bytes for the UART, all of them or (when they do not fit in the transmit
 *  buffer) none: returns false then. O(size). Main loop only. */
bool board_uart_queue(const uint8_t* data, size_t size);

/** Moves queued bytes into the UART while its transmit register is free; never waits.
 *  Main loop only. */
void board_uart_poll(void);

/** The machine's safe state: the gripper must not close further. Disables interrupts and
 *  halts; an independent watchdog (not set up by the example) would reset the controller. */
void board_fail_safe(void) __attribute__((noreturn));

#endif /* PLIANT_EXAMPLE_BOARD_H */
