/* tablebot engine: one tick of the generated table (see tb_engine.h for the semantics). */
#include "tb_engine.h"

#if TB_N_COUNTERS > 0
static TB_ROM const tb_event_t counter_bit[TB_N_COUNTERS] = TB_COUNTER_BITS;
#endif

void tb_init(tb_engine_t *e)
{
    uint8_t i;
    e->started = 0;
    e->state = TB_INITIAL_STATE;
    e->timer = TB_INITIAL_TIMER;
    e->event = 0;
    e->row = TB_NO_ROW;
    for (i = 0; i < sizeof e->out; i++)
        e->out[i] = 0;
    for (i = 0; i < sizeof e->counter / sizeof e->counter[0]; i++)
        e->counter[i] = 0;
}

tb_row_t tb_lookup_row(tb_state_t state, tb_event_t events)
{
#if TB_LOOKUP_DENSE
    /* One table entry per (state, event set): the first match, and the rule for no event, were
     * decided at generation. */
    return TB_RD_ROW(&tb_lookup[((TB_INDEX_T)state << TB_N_EVENTS) | events]);
#else
    /* The state's rows in table order, unreachable ones dropped at generation. */
    uint16_t i = TB_RD16(&tb_scan_start[state]);
    uint16_t end;
#if TB_NEEDS_EVENT
    /* The document's engine looks a row up only if an event is detected. */
    if (!events)
        return TB_NO_ROW;
#endif
    end = TB_RD16(&tb_scan_start[state + 1]);
    for (; i < end; i++) {
        tb_event_t mask = TB_RD_EVENT(&tb_scan_mask[i]);
        if ((events & mask) == mask)
            return TB_RD_ROW(&tb_scan_row[i]);
    }
    return TB_NO_ROW;
#endif
}

static uint16_t next16(const uint8_t **p)
{
    const uint8_t *q = *p;
    uint8_t lo = TB_NEXT8(q);
    uint8_t hi = TB_NEXT8(q);
    *p = q;
    return (uint16_t)(lo | (uint16_t)hi << 8);
}

static void fire(tb_engine_t *e, tb_row_t row)
{
    const uint8_t *p = &tb_actions[(TB_INDEX_T)row * TB_ACTION_BYTES];
#if TB_N_OUTPUTS > 0
    uint8_t i;
#endif
#if TB_STATE_BYTES == 1
    e->state = TB_NEXT8(p);
#else
    e->state = next16(&p);
#endif
    e->timer = next16(&p);
#if TB_N_OUTPUTS > 0
    for (i = 0; i < TB_N_OUTPUTS; i++) {
        int8_t v = (int8_t)TB_NEXT8(p);
        if (v != TB_KEEP)
            e->out[i] = v;
    }
#endif
#if TB_N_COUNTERS > 0
    {
        uint8_t loads = TB_NEXT8(p);
        uint8_t c;
        for (c = 0; c < TB_N_COUNTERS; c++) {
            uint16_t value = next16(&p);
            if (loads & (1u << c))
                e->counter[c] = value;
        }
    }
#endif
}

const int8_t *tb_tick(tb_engine_t *e, tb_event_t inputs, const uint16_t *pulses)
{
    tb_event_t events = inputs & (tb_event_t)TB_INPUT_MASK;
    uint16_t timer = e->timer;
    tb_row_t row;
#if TB_N_COUNTERS > 0
    uint8_t c;
#endif
    if (e->started) {
        if (timer)
            e->timer = --timer;
#if TB_N_COUNTERS > 0
        if (pulses)
            for (c = 0; c < TB_N_COUNTERS; c++)
                e->counter[c] = pulses[c] >= e->counter[c] ? 0 : (uint16_t)(e->counter[c] - pulses[c]);
#endif
    } else {
        e->started = 1;
    }
    (void)pulses;
#if TB_TIMER_BIT
    if (timer == 0)
        events |= (tb_event_t)TB_TIMER_BIT;
#endif
#if TB_N_COUNTERS > 0
    for (c = 0; c < TB_N_COUNTERS; c++)
        if (e->counter[c] == 0)
            events |= TB_RD_EVENT(&counter_bit[c]);
#endif
    e->event = events;
    e->row = row = tb_lookup_row(e->state, events);
    if (row != TB_NO_ROW)
        fire(e, row);
    return e->out;
}
