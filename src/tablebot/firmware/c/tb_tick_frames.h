/* What every tablebot firmware shares (tb_firmware.c, one table; tb_firmware_several.c, several): main(),
 * the tick interrupt and its timer, and the UART's ring of trace frames. One file includes it, the
 * firmware's main file, after tb_board.h and after defining
 *   TB_FRAME_TICK       the tick frame's type byte
 *   TB_FW_COUNTERS      how many encoder pulse counters the step takes
 * and then defines the hooks declared below: the engine's start and step, the outputs, and the two frames.
 *
 * Tick interrupt: sample the inputs (and encoder pulses), step, drive the outputs, queue the trace frame.
 * The UART sends from a ring buffer in its own interrupt; main() sleeps.
 * Frames (documented in docs/firmware.md):
 *   0x7E TYPE PAYLOAD CHECK   with CHECK making TYPE + PAYLOAD + CHECK sum to 0 mod 256.
 * GPIOR0 markers let an emulator count cycles: 1 tick start, 2 step start, 3 step end, 4 tick end.
 */
#ifndef TB_TICK_FRAMES_H
#define TB_TICK_FRAMES_H

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_mark.h"

#define TB_SYNC 0x7E
#define TB_FRAME_HELLO 'H'
#define TB_TX_MASK (TB_TX_SIZE - 1)

/* The hooks the firmware's main file defines. */
static inline void tb_fw_init(void);
static inline void tb_fw_step(tb_event_t inputs, const uint16_t *pulses);
static inline void tb_fw_outputs(void);
static void send_hello(void);
static void send_tick(void);

static uint16_t tick_no;
static uint8_t tx_buf[TB_TX_SIZE];
static volatile uint8_t tx_head, tx_tail;

/* A frame being written into the ring: a local, so that it lives in registers. */
typedef struct {
    uint8_t at, sum;
} frame_t;

static inline void put(frame_t *f, uint8_t b)
{
    tx_buf[f->at] = b;
    f->at = (uint8_t)((f->at + 1) & TB_TX_MASK);
    f->sum = (uint8_t)(f->sum + b);
}

static inline void put_le(frame_t *f, uint32_t v, uint8_t n)
{
    while (n--) {
        put(f, (uint8_t)v);
        v >>= 8;
    }
}

/* Start a frame of `len` payload bytes, or refuse (0) when the ring cannot take it whole:
 * the frame is dropped and the decoder sees a gap in the tick numbers. */
static inline uint8_t frame_begin(frame_t *f, uint8_t type, uint8_t len)
{
    uint8_t room = (uint8_t)((tx_tail - tx_head - 1) & TB_TX_MASK);
    if (room < (uint8_t)(len + 3))
        return 0;
    f->at = tx_head;
    put(f, TB_SYNC);
    f->sum = 0;
    put(f, type);
    return 1;
}

static inline void frame_end(frame_t *f)
{
    put(f, (uint8_t)(0 - f->sum));
    tx_head = f->at;
    TB_UCSRB |= 1 << TB_UDRIE;
}

ISR(TB_UDRE_vect)
{
    uint8_t t = tx_tail;
    if (t == tx_head) {
        TB_UCSRB &= (uint8_t)~(1 << TB_UDRIE);
        return;
    }
    TB_UDR = tx_buf[t];
    tx_tail = (uint8_t)((t + 1) & TB_TX_MASK);
}

ISR(TIMER1_COMPA_vect)
{
    tb_event_t inputs;
    uint16_t pulses[TB_FW_COUNTERS > 0 ? TB_FW_COUNTERS : 1];
    TB_MARK(1);
    inputs = tb_wiring_inputs();
    tb_wiring_pulses(pulses);
    TB_MARK(2);
    tb_fw_step(inputs, pulses);
    TB_MARK(3);
    tb_fw_outputs();
    send_tick();
    tick_no++;
    TB_MARK(4);
}

int main(void)
{
    tb_fw_init();
    tb_board_init();
    tb_wiring_init();
    tb_uart_init(TB_UBRR);
    TB_MARK(0xE0); /* two markers back to back: the emulator's measure of marker overhead */
    TB_MARK(0xE1);
    send_hello();
    OCR1A = TB_TICK_TOP;
    TCCR1A = 0;
    TCCR1B = (1 << WGM12) | TB_TICK_CS; /* CTC: an interrupt every tick */
    TIMSK1 = 1 << OCIE1A;
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    for (;;)
        sleep_mode();
}

#endif
