/* A host program around the generated engine of a robot of several tables (tb_robot.h), for tests and for
 * trying a robot on a PC.
 *
 * Reads one tick per line from standard input: the input mask (the robot's input layout) followed by the
 * pulses of each counter; writes one line per tick: per table its event, row (-1: none), state index and
 * timer, then every output and every counter of the robot.
 * Build: cc -std=c99 host_several.c tb_robot.c tb_table_*.c
 */
#include <stdio.h>

#include "tb_robot.h"

int main(void)
{
    tb_robot_t robot;
    unsigned long mask;
    uint16_t pulses[TB_ROBOT_N_COUNTERS > 0 ? TB_ROBOT_N_COUNTERS : 1] = {0};
    unsigned i;

    tb_robot_init(&robot);
    while (scanf("%lu", &mask) == 1) {
#if TB_ROBOT_N_COUNTERS > 0
        for (i = 0; i < TB_ROBOT_N_COUNTERS; i++) {
            unsigned value = 0;
            if (scanf("%u", &value) != 1)
                return 2;
            pulses[i] = (uint16_t)value;
        }
#endif
        tb_robot_tick(&robot, (uint32_t)mask, pulses);
        for (i = 0; i < TB_ROBOT_N_TABLES; i++)
            printf("%s%lu %ld %u %u", i ? " " : "", (unsigned long)robot.table[i].event, (long)robot.table[i].row,
                   (unsigned)robot.table[i].state, (unsigned)robot.table[i].timer);
#if TB_ROBOT_N_OUTPUTS > 0
        for (i = 0; i < TB_ROBOT_N_OUTPUTS; i++)
            printf(" %d", robot.out[i]);
#endif
#if TB_ROBOT_N_COUNTERS > 0
        for (i = 0; i < TB_ROBOT_N_COUNTERS; i++)
            printf(" %u", (unsigned)robot.counter[i]);
#endif
        putchar('\n');
    }
    return 0;
}
