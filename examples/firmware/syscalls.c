/* The C library hooks this firmware provides, and nothing more (no file I/O, no stdio).
 *
 * abort(): pliant's default assert handler (core/src/status.cpp) calls it. newlib's abort goes
 * through raise(), whose signal table is allocated with malloc on first use: linking it would
 * link the heap. Here abort is what it must be on a controller: the safe state.
 *
 * _sbrk(): there is no heap. Nothing in the image calls malloc (tools/cross.sh checks with nm
 * that no allocator is linked); should one slip in, it gets NULL instead of growing into RAM
 * that belongs to something else. */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "board.h"

void* _sbrk(ptrdiff_t increment);

void abort(void) { board_fail_safe(); }

void* _sbrk(ptrdiff_t increment) {
  (void)increment;
  errno = ENOMEM;
  return (void*)(intptr_t)-1;
}
