/* A host program around the generated engine, for tests and for trying a table on a PC.
 *
 * Reads one tick per line from standard input: the input mask (event layout) followed by
 * the pulses of each counter; writes one line per tick: event, row (-1: none), state index,
 * timer, every output, every counter. Build: cc -std=c99 host_run.c tb_engine.c tb_table.c
 */
#include <stdio.h>

#include "tb_engine.h"

int main(void)
{
    tb_engine_t engine;
    unsigned long mask;
    uint16_t pulses[TB_N_COUNTERS > 0 ? TB_N_COUNTERS : 1] = {0};
    unsigned i;

    tb_init(&engine);
    while (scanf("%lu", &mask) == 1) {
#if TB_N_COUNTERS > 0
        for (i = 0; i < TB_N_COUNTERS; i++) {
            unsigned value = 0;
            if (scanf("%u", &value) != 1)
                return 2;
            pulses[i] = (uint16_t)value;
        }
#endif
        tb_tick(&engine, (tb_event_t)mask, pulses);
        printf("%lu %ld %u %u", (unsigned long)engine.event,
               engine.row == TB_NO_ROW ? -1L : (long)engine.row, (unsigned)engine.state,
               (unsigned)engine.timer);
#if TB_N_OUTPUTS > 0
        for (i = 0; i < TB_N_OUTPUTS; i++)
            printf(" %d", engine.out[i]);
#endif
#if TB_N_COUNTERS > 0
        for (i = 0; i < TB_N_COUNTERS; i++)
            printf(" %u", (unsigned)engine.counter[i]);
#endif
        putchar('\n');
    }
    return 0;
}
