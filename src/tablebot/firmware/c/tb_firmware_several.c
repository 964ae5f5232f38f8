/* tablebot firmware of a robot of several tables (tb_robot.h): every table runs in a timer interrupt every
 * tick (10 ms by default) and each tick's trace goes out over the UART as one frame.
 *
 * Tick interrupt: sample the inputs (the robot's input layout) and encoder pulses, tb_robot_tick() (every
 * table, cross-table events from the states at the start of the tick, each output from its one writer),
 * drive the outputs, queue the trace frame. The UART sends from a ring buffer in its own interrupt.
 * Frames (decoded by tablebot.firmware.several, documented in docs/firmware.md):
 *   0x7E TYPE PAYLOAD CHECK   with CHECK making TYPE + PAYLOAD + CHECK sum to 0 mod 256.
 *   'H' hello, once at start: version (2: several tables), tables, outputs, counters.
 *   'S' tick: tick number (16 bit), per table its event (32 bit), row (16 bit, -1: none), state and timer
 *       (16 bit each), then the robot's outputs (int8) and counters (16 bit), all little-endian.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_robot.h"

typedef uint32_t tb_event_t; /* the robot's input mask, as tb_board.h samples it */

#include "tb_board.h"

#define TB_SYNC 0x7E
#define TB_FRAME_HELLO 'H'
#define TB_FRAME_TICK 'S'
#define TB_FRAME_VERSION 2
#define TB_TX_MASK (TB_TX_SIZE - 1)

#define TB_MARK(v)                                   \
    do {                                             \
        __asm__ __volatile__("" ::: "memory");       \
        GPIOR0 = (v);                                \
        __asm__ __volatile__("" ::: "memory");       \
    } while (0)

static tb_robot_t robot;
static uint16_t tick_no;
static uint8_t tx_buf[TB_TX_SIZE];
static volatile uint8_t tx_head, tx_tail;

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

/* Start a frame, or refuse (0) when the ring cannot take it whole: the decoder sees a gap. */
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

static void send_hello(void)
{
    frame_t f;
    if (!frame_begin(&f, TB_FRAME_HELLO, 4))
        return;
    put(&f, TB_FRAME_VERSION);
    put(&f, TB_ROBOT_N_TABLES);
    put(&f, TB_ROBOT_N_OUTPUTS);
    put(&f, TB_ROBOT_N_COUNTERS);
    frame_end(&f);
}

static void send_tick(void)
{
    uint8_t i;
    frame_t f;
    if (!frame_begin(&f, TB_FRAME_TICK, TB_TICK_PAYLOAD))
        return;
    put_le(&f, tick_no, 2);
    for (i = 0; i < TB_ROBOT_N_TABLES; i++) {
        put_le(&f, robot.table[i].event, 4);
        put_le(&f, (uint16_t)robot.table[i].row, 2);
        put_le(&f, robot.table[i].state, 2);
        put_le(&f, robot.table[i].timer, 2);
    }
#if TB_ROBOT_N_OUTPUTS > 0
    for (i = 0; i < TB_ROBOT_N_OUTPUTS; i++)
        put(&f, (uint8_t)robot.out[i]);
#endif
#if TB_ROBOT_N_COUNTERS > 0
    for (i = 0; i < TB_ROBOT_N_COUNTERS; i++)
        put_le(&f, robot.counter[i], 2);
#endif
    frame_end(&f);
}

ISR(TIMER1_COMPA_vect)
{
    tb_event_t inputs;
    uint16_t pulses[TB_ROBOT_N_COUNTERS > 0 ? TB_ROBOT_N_COUNTERS : 1];
    TB_MARK(1);
    inputs = tb_wiring_inputs();
    tb_wiring_pulses(pulses);
    TB_MARK(2);
    tb_robot_tick(&robot, inputs, pulses);
    TB_MARK(3);
    tb_wiring_outputs(robot.out);
    send_tick();
    tick_no++;
    TB_MARK(4);
}

int main(void)
{
    tb_robot_init(&robot);
    tb_board_init();
    tb_wiring_init();
    tb_uart_init(TB_UBRR);
    TB_MARK(0xE0);
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
