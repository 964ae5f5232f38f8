/* GPIOR0 markers an emulator counts cycles between (tablebot.firmware.emulate): the firmware's tick and
 * step, the benchmark's step. The barriers keep the compiler from moving work across a marker. */
#ifndef TB_MARK_H
#define TB_MARK_H

#include <avr/io.h>

#define TB_MARK(v)                                   \
    do {                                             \
        __asm__ __volatile__("" ::: "memory");       \
        GPIOR0 = (v);                                \
        __asm__ __volatile__("" ::: "memory");       \
    } while (0)

#endif
