/* tablebot step benchmark: times tb_tick() for every (state, event set) pair of the table, so the
 * first-match worst case is measured, not hoped for. No board: an emulator reads the GPIOR0
 * markers (2 before, 3 after each step; 0xE0, 0xE1 back to back for the marker overhead).
 * The engine is put straight into each pair: started, timer 1 (T wanted) or 2, each counter 0
 * (its event wanted) or 1, no pulses; the inputs are read from a volatile after the start
 * marker, so the step cannot be prepared ahead. Ends with interrupts off and the CPU asleep.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>

#include "tb_engine.h"
#include "tb_mark.h"

#ifndef TB_BENCH_MAX_EVENTS
#define TB_BENCH_MAX_EVENTS 4096UL /* event sets per state: all of them up to 12 event columns */
#endif

static tb_engine_t engine;
static volatile tb_event_t bench_inputs;
#if TB_N_COUNTERS > 0
static const tb_event_t bench_counter_bits[TB_N_COUNTERS] = TB_COUNTER_BITS;
#endif

static void set_up(uint16_t state, uint32_t events)
{
#if TB_N_COUNTERS > 0
    uint8_t c;
    for (c = 0; c < TB_N_COUNTERS; c++)
        engine.counter[c] = (events & bench_counter_bits[c]) ? 0 : 1;
#endif
    engine.started = 1;
    engine.state = (tb_state_t)state;
    engine.timer = (events & TB_TIMER_BIT) ? 1 : 2;
    bench_inputs = (tb_event_t)events;
}

int main(void)
{
    uint16_t pulses[TB_N_COUNTERS > 0 ? TB_N_COUNTERS : 1] = {0};
    uint16_t state;
    uint32_t events;
    tb_init(&engine);
    TB_MARK(0xE0);
    TB_MARK(0xE1);
    for (state = 0; state < TB_N_STATES; state++) {
        for (events = 0; events < (1UL << TB_N_EVENTS) && events < TB_BENCH_MAX_EVENTS; events++) {
            set_up(state, events);
            TB_MARK(2);
            tb_tick(&engine, bench_inputs, pulses);
            TB_MARK(3);
        }
    }
    cli();
    sleep_cpu();
    for (;;) {
    }
}
