/* tablebot firmware: the generated table runs in a timer interrupt every tick (10 ms by default)
 * and each tick's trace goes out over the UART as one frame (tb_tick_frames.h: main, the tick
 * interrupt, the frame ring). Frames (decoded by tablebot.firmware.framing, docs/firmware.md):
 *   'H' hello, once at start: version, table hash, states, rows, event bytes, outputs, counters,
 *       tick in ms.
 *   'T' tick: tick number (16 bit), event, row, state, timer, outputs (int8), counters (16 bit),
 *       all little-endian, widths as in tb_config.h.
 */
#include <avr/interrupt.h> /* before tb_board.h: its encoder interrupts */
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_engine.h"
#include "tb_board.h"

#define TB_FRAME_TICK 'T'
#define TB_FRAME_VERSION 1
#define TB_FW_COUNTERS TB_N_COUNTERS

#include "tb_tick_frames.h"

static tb_engine_t engine;

static inline void tb_fw_init(void)
{
    tb_init(&engine);
}

static inline void tb_fw_step(tb_event_t inputs, const uint16_t *pulses)
{
    tb_tick(&engine, inputs, pulses);
}

static inline void tb_fw_outputs(void)
{
    tb_wiring_outputs(engine.out);
}

static void send_hello(void)
{
    frame_t f;
    if (!frame_begin(&f, TB_FRAME_HELLO, 12))
        return;
    put(&f, TB_FRAME_VERSION);
    put_le(&f, TB_TABLE_HASH, 4);
    put_le(&f, TB_N_STATES, 2);
    put_le(&f, TB_N_ROWS, 2);
    put(&f, sizeof(tb_event_t));
    put(&f, TB_N_OUTPUTS);
    put(&f, TB_N_COUNTERS);
    frame_end(&f);
}

static void send_tick(void)
{
#if TB_N_OUTPUTS > 0 || TB_N_COUNTERS > 0
    uint8_t i;
#endif
    frame_t f;
    if (!frame_begin(&f, TB_FRAME_TICK, TB_TICK_PAYLOAD))
        return;
    put_le(&f, tick_no, 2);
    put_le(&f, engine.event, sizeof(tb_event_t));
    put_le(&f, engine.row, sizeof(tb_row_t));
    put_le(&f, engine.state, sizeof(tb_state_t));
    put_le(&f, engine.timer, 2);
#if TB_N_OUTPUTS > 0
    for (i = 0; i < TB_N_OUTPUTS; i++)
        put(&f, (uint8_t)engine.out[i]);
#endif
#if TB_N_COUNTERS > 0
    for (i = 0; i < TB_N_COUNTERS; i++)
        put_le(&f, engine.counter[i], 2);
#endif
    frame_end(&f);
}
