/* tablebot engine: the document's transition-table engine in portable C99.
 *
 * No heap, no floating point. The table and its compiled first-match lookup are const
 * data (PROGMEM on AVR). One call of tb_tick() is one engine tick:
 *   - after the first tick the timer counts down (never below 0) and each counter counts
 *     down by the encoder pulses since the last tick (never below 0);
 *   - the event set is the inputs that read 1, plus T when the timer is 0, plus Cn when
 *     counter n is 0 (event columns in table order, first column = highest bit);
 *   - the first row of the current state whose required events are all present fires:
 *     outputs (TB_KEEP = leave as it is), timer load, counter loads, next state.
 *     No matching row: nothing changes. With TB_NEEDS_EVENT (the robot file's
 *     match = "document") a tick with no event at all looks up no row, as in the document.
 * tb_config.h and tb_table.c are generated per table; this file and tb_engine.c are not.
 */
#ifndef TB_ENGINE_H
#define TB_ENGINE_H

#include <stdint.h>

#if defined(__AVR__)
#include <avr/pgmspace.h>
#define TB_ROM PROGMEM
#define TB_RD8(p) pgm_read_byte(p)
#define TB_RD16(p) pgm_read_word(p)
#define TB_RD32(p) pgm_read_dword(p)
/* Read one flash byte and advance the pointer: one LPM Z+ instruction. */
#define TB_NEXT8(p) __extension__({ uint8_t v_; __asm__("lpm %0, Z+" : "=r"(v_), "+z"(p)); v_; })
#else
#define TB_ROM
#define TB_RD8(p) (*(const uint8_t *)(p))
#define TB_RD16(p) (*(const uint16_t *)(p))
#define TB_RD32(p) (*(const uint32_t *)(p))
#define TB_NEXT8(p) (*(p)++)
#endif

#include "tb_config.h"

/* An output value of TB_KEEP leaves that output as it is. */
#define TB_KEEP (-128)

/* What a row does when it fires, TB_ACTION_BYTES per row, little-endian and unpadded so that
 * fire() reads it front to back: next state (tb_state_t), timer (2 bytes), one signed byte per
 * output (TB_KEEP: leave it), then, with counters, a byte of load flags and 2 bytes per counter. */
#define TB_ACTION_BYTES (sizeof(tb_state_t) + 2 + TB_N_OUTPUTS + (TB_N_COUNTERS > 0 ? 1 + 2 * TB_N_COUNTERS : 0))

/* The whole runtime state: plain data, so it can be saved and compared. */
typedef struct {
    uint8_t started;   /* 0 before the first tick: the timer does not count down on it */
    tb_state_t state;  /* index into the table's states */
    uint16_t timer;
    tb_event_t event;  /* events of the last tick */
    tb_row_t row;      /* row fired in the last tick, TB_NO_ROW if none */
    int8_t out[TB_N_OUTPUTS > 0 ? TB_N_OUTPUTS : 1];
    uint16_t counter[TB_N_COUNTERS > 0 ? TB_N_COUNTERS : 1];
} tb_engine_t;

extern TB_ROM const uint8_t tb_actions[TB_N_ROWS * TB_ACTION_BYTES];
#if TB_LOOKUP_DENSE
extern TB_ROM const tb_row_t tb_lookup[(uint32_t)TB_N_STATES << TB_N_EVENTS];
#else
extern TB_ROM const uint16_t tb_scan_start[TB_N_STATES + 1];
extern TB_ROM const tb_event_t tb_scan_mask[TB_N_SCAN];
extern TB_ROM const tb_row_t tb_scan_row[TB_N_SCAN];
#endif

/* Reset to the initial state: outputs 0, counters 0, timer TB_INITIAL_TIMER. */
void tb_init(tb_engine_t *e);

/* The row that fires in `state` for `events`, or TB_NO_ROW. */
tb_row_t tb_lookup_row(tb_state_t state, tb_event_t events);

/* One tick. `inputs` are input bits in event layout (other bits are ignored); `pulses` holds
 * encoder pulses per counter since the last tick (NULL: none). Returns the outputs. */
const int8_t *tb_tick(tb_engine_t *e, tb_event_t inputs, const uint16_t *pulses);

#endif
