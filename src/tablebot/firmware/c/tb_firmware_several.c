/* tablebot firmware of a robot of several tables (tb_robot.h): every table runs in a timer interrupt every
 * tick (10 ms by default) and each tick's trace goes out over the UART as one frame (tb_tick_frames.h: main,
 * the tick interrupt, the frame ring). The step is tb_robot_tick(): every table, cross-table events from the
 * states at the start of the tick, each output from its one writer.
 * Frames (decoded by tablebot.firmware.several, documented in docs/firmware.md):
 *   'H' hello, once at start: version (2: several tables), tables, outputs, counters.
 *   'S' tick: tick number (16 bit), per table its event (32 bit), row (16 bit, -1: none), state and timer
 *       (16 bit each), then the robot's outputs (int8) and counters (16 bit), all little-endian.
 */
#include <avr/interrupt.h> /* before tb_board.h: its encoder interrupts */
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_robot.h"

typedef uint32_t tb_event_t; /* the robot's input mask, as tb_board.h samples it */

#include "tb_board.h"

#define TB_FRAME_TICK 'S'
#define TB_FRAME_VERSION 2
#define TB_FW_COUNTERS TB_ROBOT_N_COUNTERS

#include "tb_tick_frames.h"

static tb_robot_t robot;

static inline void tb_fw_init(void)
{
    tb_robot_init(&robot);
}

static inline void tb_fw_step(tb_event_t inputs, const uint16_t *pulses)
{
    tb_robot_tick(&robot, inputs, pulses);
}

static inline void tb_fw_outputs(void)
{
    tb_wiring_outputs(robot.out);
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
