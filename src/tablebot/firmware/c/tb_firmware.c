/* tablebot firmware: the generated table runs in a timer interrupt every tick (10 ms by default)
 * and each tick's trace goes out over the UART as one frame.
 *
 * Tick interrupt: sample the inputs (and encoder pulses), tb_tick(), drive the outputs, queue
 * the trace frame. The UART sends from a ring buffer in its own interrupt; main() sleeps.
 * Frames (decoded by tablebot.firmware.framing, documented in docs/firmware.md):
 *   0x7E TYPE PAYLOAD CHECK   with CHECK making TYPE + PAYLOAD + CHECK sum to 0 mod 256.
 *   'H' hello, once at start: version, table hash, states, rows, event bytes, outputs, counters,
 *       tick in ms.
 *   'T' tick: tick number (16 bit), event, row, state, timer, outputs (int8), counters (16 bit),
 *       all little-endian, widths as in tb_config.h.
 * GPIOR0 markers let an emulator count cycles: 1 tick start, 2 step start, 3 step end, 4 tick end.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_engine.h"
#include "tb_board.h"

#define TB_SYNC 0x7E
#define TB_FRAME_HELLO 'H'
#define TB_FRAME_TICK 'T'
#define TB_FRAME_VERSION 1
#define TB_TX_MASK (TB_TX_SIZE - 1)

/* The barriers keep the compiler from moving work across a marker. */
#define TB_MARK(v)                                   \
    do {                                             \
        __asm__ __volatile__("" ::: "memory");       \
        GPIOR0 = (v);                                \
        __asm__ __volatile__("" ::: "memory");       \
    } while (0)

static tb_engine_t engine;
static uint16_t tick_no;
static uint8_t tx_buf[TB_TX_SIZE];
static volatile uint8_t tx_head, tx_tail;
static uint8_t frame_at, frame_sum;

static void put(uint8_t b)
{
    tx_buf[frame_at] = b;
    frame_at = (uint8_t)((frame_at + 1) & TB_TX_MASK);
    frame_sum = (uint8_t)(frame_sum + b);
}

static void put_le(uint32_t v, uint8_t n)
{
    while (n--) {
        put((uint8_t)v);
        v >>= 8;
    }
}

/* Start a frame of `len` payload bytes, or refuse (0) when the ring cannot take it whole:
 * the frame is dropped and the decoder sees a gap in the tick numbers. */
static uint8_t frame_begin(uint8_t type, uint8_t len)
{
    uint8_t room = (uint8_t)((tx_tail - tx_head - 1) & TB_TX_MASK);
    if (room < (uint8_t)(len + 3))
        return 0;
    frame_at = tx_head;
    put(TB_SYNC);
    frame_sum = 0;
    put(type);
    return 1;
}

static void frame_end(void)
{
    put((uint8_t)(0 - frame_sum));
    tx_head = frame_at;
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

static void send_hello(void)
{
    if (!frame_begin(TB_FRAME_HELLO, 12))
        return;
    put(TB_FRAME_VERSION);
    put_le(TB_TABLE_HASH, 4);
    put_le(TB_N_STATES, 2);
    put_le(TB_N_ROWS, 2);
    put(sizeof(tb_event_t));
    put(TB_N_OUTPUTS);
    put(TB_N_COUNTERS);
    frame_end();
}

static void send_tick(void)
{
#if TB_N_OUTPUTS > 0 || TB_N_COUNTERS > 0
    uint8_t i;
#endif
    if (!frame_begin(TB_FRAME_TICK, TB_TICK_PAYLOAD))
        return;
    put_le(tick_no, 2);
    put_le(engine.event, sizeof(tb_event_t));
    put_le(engine.row, sizeof(tb_row_t));
    put_le(engine.state, sizeof(tb_state_t));
    put_le(engine.timer, 2);
#if TB_N_OUTPUTS > 0
    for (i = 0; i < TB_N_OUTPUTS; i++)
        put((uint8_t)engine.out[i]);
#endif
#if TB_N_COUNTERS > 0
    for (i = 0; i < TB_N_COUNTERS; i++)
        put_le(engine.counter[i], 2);
#endif
    frame_end();
}

ISR(TIMER1_COMPA_vect)
{
    tb_event_t inputs;
    uint16_t pulses[TB_N_COUNTERS > 0 ? TB_N_COUNTERS : 1];
    TB_MARK(1);
    inputs = tb_wiring_inputs();
    tb_wiring_pulses(pulses);
    TB_MARK(2);
    tb_tick(&engine, inputs, pulses);
    TB_MARK(3);
    tb_wiring_outputs(engine.out);
    send_tick();
    tick_no++;
    TB_MARK(4);
}

int main(void)
{
    tb_init(&engine);
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
