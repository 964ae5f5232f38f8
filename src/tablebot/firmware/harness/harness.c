/* tablebot emulation harness: runs a firmware ELF under libsimavr, drives its input pins tick by
 * tick from a CSV, captures the UART and counts exact CPU cycles from GPIOR0 markers.
 *
 * Build: cc -O2 $(pkg-config --cflags simavr) harness.c -lsimavr -lelf -o harness
 * Usage: harness --elf FW.elf --mcu atmega328p [--freq 16000000] [--uart 0|1]
 *                [--inputs PINS.csv --ticks-out TICKS.csv] [--marks-out MARKS.csv]
 *                [--uart-out UART.bin] [--flush-ms 5] [--max-ms 100000]
 *
 * PINS.csv: a header of driven signals, then one row per tick, applied after the previous tick's
 * interrupt ended (row 0 before start). Columns: PD2 = digital level of port D pin 2; ADC6 =
 * millivolts on ADC channel 6; ~PC4 = rising edges on port C pin 4 before that tick (pin idles
 * high; row 0's pulses are not sent: the engine ignores the first tick's pulses).
 * Firmware markers (GPIOR0 writes): 0xE0, 0xE1 back to back at start (marker overhead);
 * 1 tick start, 2 step start, 3 step end, 4 tick end.
 * TICKS.csv: tick,entry,m1,m2,m3,m4,exit (cycles; entry/exit: interrupt taken / returned).
 * MARKS.csv (no inputs: runs until the firmware sleeps with interrupts off): value,cycle per write.
 * ADC readings come from the harness, not from simavr's converter: the firmware's ADCL/ADCH reads
 * return the CSV's millivolts (5 V reference, 10 bits) of the channel that ADMUX and ADCSRB's
 * MUX5 select, because simavr 1.6's ATmega32U4 model cannot select ADC8..ADC11. simavr still
 * times the conversions and raises their interrupts.
 * Sleep runs at full speed: the harness replaces simavr's real-time sleep with nothing, so
 * simavr jumps straight to its next timer event.
 * Exit status: 0 ok, 2 usage or file error, 3 emulation error.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avr_adc.h"
#include "avr_ioport.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_io.h"

#define GPIOR0_ADDR 0x3E /* data-space address on the ATmega328P and ATmega32U4 */
#define MAX_COLUMNS 40
#define PULSE_HALF_CYCLES 200
#define ADCL_ADDR 0x78 /* same on the ATmega328P and ATmega32U4 */
#define ADCH_ADDR 0x79
#define ADCSRB_ADDR 0x7B
#define ADMUX_ADDR 0x7C
#define ADC_CHANNELS 16

enum kind { DIGITAL, ADC, PULSES };

typedef struct {
    enum kind kind;
    char port;
    int bit;     /* pin bit, or ADC channel */
    int pending; /* pulses still to send */
    int low;     /* pulse in progress: pin held low */
} column_t;

typedef struct {
    uint64_t entry, m[4], exit;
} tick_t;

static avr_t *avr;
static column_t columns[MAX_COLUMNS];
static int n_columns;
static long *rows; /* n_rows * n_columns values */
static int n_rows;
static tick_t *ticks;
static int ticks_done, in_tick;
static uint64_t calib_start, calib, next_pulse_at;
static uint8_t ext_mask[8], ext_value[8];
static uint8_t *uart_buf;
static size_t uart_len, uart_cap;
static FILE *marks_out;
static uint32_t adc_mv[ADC_CHANNELS];

static void die(int code, const char *message, const char *detail)
{
    fprintf(stderr, "harness: %s%s%s\n", message, detail ? ": " : "", detail ? detail : "");
    exit(code);
}

static void sleep_skip(avr_t *a, avr_cycle_count_t how_long)
{
    (void)a; /* no real-time sleeping: simavr jumps to the next timer event */
    (void)how_long;
}

/* --- input CSV ----------------------------------------------------------------------------- */

static void parse_column(const char *name, column_t *c)
{
    memset(c, 0, sizeof *c);
    if (name[0] == '~') {
        c->kind = PULSES;
        name++;
    } else if (strncmp(name, "ADC", 3) == 0) {
        c->kind = ADC;
        c->bit = atoi(name + 3);
        return;
    }
    if (name[0] != 'P' || name[1] < 'A' || name[1] > 'H' || name[2] < '0' || name[2] > '7')
        die(2, "bad input column (want PD2, ADC6 or ~PC4)", name);
    c->port = name[1];
    c->bit = name[2] - '0';
}

static void read_inputs(const char *path)
{
    char line[1024];
    int cap = 0;
    FILE *f = fopen(path, "r");
    if (!f)
        die(2, "cannot open inputs", path);
    if (!fgets(line, sizeof line, f))
        die(2, "empty inputs file", path);
    for (char *tok = strtok(line, ",\r\n"); tok; tok = strtok(NULL, ",\r\n")) {
        if (n_columns == MAX_COLUMNS)
            die(2, "too many input columns", path);
        parse_column(tok, &columns[n_columns++]);
    }
    while (fgets(line, sizeof line, f)) {
        char *p = line;
        if (n_rows == cap) {
            cap = cap ? 2 * cap : 1024;
            rows = realloc(rows, (size_t)cap * (size_t)(n_columns ? n_columns : 1) * sizeof *rows);
        }
        for (int i = 0; i < n_columns; i++) {
            rows[n_rows * n_columns + i] = strtol(p, &p, 10);
            if (*p == ',')
                p++;
        }
        n_rows++;
    }
    fclose(f);
}

/* --- driving pins ------------------------------------------------------------------------- */

static void drive(char port, int bit, int level)
{
    int i = port - 'A';
    avr_ioport_external_t ext;
    ext_mask[i] |= (uint8_t)(1u << bit);
    ext_value[i] = (uint8_t)((ext_value[i] & ~(1u << bit)) | ((level ? 1u : 0u) << bit));
    ext.name = (unsigned)port;
    ext.mask = ext_mask[i];
    ext.value = ext_value[i];
    /* the external level survives the firmware's own PORT writes (its pull-ups) */
    avr_ioctl(avr, AVR_IOCTL_IOPORT_SET_EXTERNAL(port), &ext);
    avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), level ? 1 : 0);
}

static void apply_row(int r)
{
    for (int i = 0; i < n_columns; i++) {
        column_t *c = &columns[i];
        long v = rows[r * n_columns + i];
        if (c->kind == DIGITAL)
            drive(c->port, c->bit, v != 0);
        else if (c->kind == ADC)
            adc_mv[c->bit & (ADC_CHANNELS - 1)] = (uint32_t)v;
        else if (r == 0)
            drive(c->port, c->bit, 1); /* idle high */
        else
            c->pending = (int)v;
    }
    next_pulse_at = avr->cycle + PULSE_HALF_CYCLES;
}

/* One half pulse on each counter pin still owed pulses: low, then high (the rising edge). */
static void step_pulses(void)
{
    if (avr->cycle < next_pulse_at)
        return;
    for (int i = 0; i < n_columns; i++) {
        column_t *c = &columns[i];
        if (c->kind != PULSES || (!c->pending && !c->low))
            continue;
        if (c->low) {
            drive(c->port, c->bit, 1);
            c->low = 0;
            c->pending--;
        } else {
            drive(c->port, c->bit, 0);
            c->low = 1;
        }
    }
    next_pulse_at = avr->cycle + PULSE_HALF_CYCLES;
}

static int pulses_owed(void)
{
    for (int i = 0; i < n_columns; i++)
        if (columns[i].pending || columns[i].low)
            return 1;
    return 0;
}

/* --- ADC --------------------------------------------------------------------------------- */

static uint16_t adc_result(avr_t *a)
{
    uint8_t mux = a->data[ADMUX_ADDR] & 0x1F;
    int channel = (a->data[ADCSRB_ADDR] & 0x20) ? 8 + (mux & 7) : mux;
    uint32_t value = adc_mv[channel & (ADC_CHANNELS - 1)] * 1024 / 5000;
    return (uint16_t)(value > 1023 ? 1023 : value);
}

static uint8_t read_adcl(avr_t *a, avr_io_addr_t addr, void *param)
{
    (void)addr;
    (void)param;
    return (uint8_t)adc_result(a);
}

static uint8_t read_adch(avr_t *a, avr_io_addr_t addr, void *param)
{
    (void)addr;
    (void)param;
    return (uint8_t)(adc_result(a) >> 8);
}

/* Replace simavr's own read handlers (the API would refuse a second one). */
static void take_over_adc(void)
{
    avr->io[AVR_DATA_TO_IO(ADCL_ADDR)].r.c = read_adcl;
    avr->io[AVR_DATA_TO_IO(ADCH_ADDR)].r.c = read_adch;
}

/* --- markers and UART --------------------------------------------------------------------- */

static void on_marker(avr_t *a, avr_io_addr_t addr, uint8_t v, void *param)
{
    (void)param;
    a->data[addr] = v;
    if (marks_out)
        fprintf(marks_out, "%u,%llu\n", v, (unsigned long long)a->cycle);
    if (v == 0xE0)
        calib_start = a->cycle;
    else if (v == 0xE1)
        calib = a->cycle - calib_start;
    if (!rows || v < 1 || v > 4)
        return;
    if (v == 1) {
        if (pulses_owed())
            die(3, "a tick started before its encoder pulses were sent", NULL);
        in_tick = 1;
    }
    if (ticks_done < n_rows)
        ticks[ticks_done].m[v - 1] = a->cycle;
    if (v == 4 && ++ticks_done < n_rows)
        apply_row(ticks_done);
}

static void on_uart(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    (void)param;
    if (uart_len == uart_cap) {
        uart_cap = uart_cap ? 2 * uart_cap : 65536;
        uart_buf = realloc(uart_buf, uart_cap);
    }
    uart_buf[uart_len++] = (uint8_t)value;
}

static void quiet_uart(char name)
{
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS(name), &flags);
    flags &= ~(uint32_t)AVR_UART_FLAG_STDIO;
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS(name), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ(name), UART_IRQ_OUTPUT), on_uart, NULL);
}

/* --- main loop ---------------------------------------------------------------------------- */

static void load(const char *elf, const char *mcu, uint32_t freq)
{
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(elf, &fw))
        die(2, "cannot read ELF", elf);
    strncpy(fw.mmcu, mcu, sizeof fw.mmcu - 1);
    fw.frequency = freq;
    avr = avr_make_mcu_by_name(mcu);
    if (!avr)
        die(2, "unknown MCU", mcu);
    avr_init(avr);
    avr_load_firmware(avr, &fw);
    avr->frequency = freq;
    avr->sleep = sleep_skip;
    avr->log = LOG_ERROR;
    avr_register_io_write(avr, GPIOR0_ADDR, on_marker, NULL);
}

/* Run until every tick is done (plus the UART flush) or the firmware stops; watch the I flag
 * to time the whole tick interrupt. */
static void run(uint64_t flush_cycles, uint64_t max_cycles)
{
    uint64_t end_at = 0, entry = 0;
    int was_enabled = avr->sreg[S_I];
    for (;;) {
        int state = avr_run(avr);
        int enabled = avr->sreg[S_I];
        if (state == cpu_Done)
            break;
        if (state == cpu_Crashed)
            die(3, "the firmware crashed", NULL);
        if (was_enabled && !enabled) {
            entry = avr->cycle;
        } else if (!was_enabled && enabled && in_tick) {
            int t = ticks_done - 1;
            in_tick = 0;
            if (t >= 0 && t < n_rows) {
                ticks[t].entry = entry;
                ticks[t].exit = avr->cycle;
            }
        }
        was_enabled = enabled;
        if (rows) {
            step_pulses();
            if (ticks_done >= n_rows && !in_tick && !end_at)
                end_at = avr->cycle + flush_cycles;
            if (end_at && avr->cycle >= end_at)
                break;
        }
        if (avr->cycle > max_cycles)
            die(3, "the emulation ran past --max-ms", NULL);
    }
}

static void write_outputs(const char *ticks_path, const char *uart_path)
{
    if (ticks_path) {
        FILE *f = fopen(ticks_path, "w");
        if (!f)
            die(2, "cannot write", ticks_path);
        fprintf(f, "# marker overhead %llu\n", (unsigned long long)calib);
        for (int t = 0; t < ticks_done && t < n_rows; t++)
            fprintf(f, "%d,%llu,%llu,%llu,%llu,%llu,%llu\n", t, (unsigned long long)ticks[t].entry,
                    (unsigned long long)ticks[t].m[0], (unsigned long long)ticks[t].m[1],
                    (unsigned long long)ticks[t].m[2], (unsigned long long)ticks[t].m[3],
                    (unsigned long long)ticks[t].exit);
        fclose(f);
    }
    if (uart_path) {
        FILE *f = fopen(uart_path, "wb");
        if (!f)
            die(2, "cannot write", uart_path);
        if (uart_len)
            fwrite(uart_buf, 1, uart_len, f);
        fclose(f);
    }
}

int main(int argc, char **argv)
{
    const char *elf = NULL, *mcu = "atmega328p", *inputs = NULL, *ticks_path = NULL;
    const char *uart_path = NULL, *marks_path = NULL;
    uint32_t freq = 16000000;
    char uart = '0';
    double flush_ms = 5, max_ms = 100000;
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *k = argv[i], *v = argv[i + 1];
        if (!strcmp(k, "--elf")) elf = v;
        else if (!strcmp(k, "--mcu")) mcu = v;
        else if (!strcmp(k, "--freq")) freq = (uint32_t)strtoul(v, NULL, 10);
        else if (!strcmp(k, "--uart")) uart = v[0];
        else if (!strcmp(k, "--inputs")) inputs = v;
        else if (!strcmp(k, "--ticks-out")) ticks_path = v;
        else if (!strcmp(k, "--marks-out")) marks_path = v;
        else if (!strcmp(k, "--uart-out")) uart_path = v;
        else if (!strcmp(k, "--flush-ms")) flush_ms = atof(v);
        else if (!strcmp(k, "--max-ms")) max_ms = atof(v);
        else die(2, "unknown option", k);
    }
    if (!elf || (argc % 2) == 0)
        die(2, "usage: harness --elf FW.elf [--mcu M] [--inputs PINS.csv] ... (see harness.c)", NULL);
    load(elf, mcu, freq);
    quiet_uart(uart);
    if (marks_path && !(marks_out = fopen(marks_path, "w")))
        die(2, "cannot write", marks_path);
    if (inputs) {
        read_inputs(inputs);
        if (!n_rows)
            die(2, "the inputs file has no rows", inputs);
        ticks = calloc((size_t)n_rows, sizeof *ticks);
        for (int i = 0; i < n_columns; i++)
            if (columns[i].kind == ADC)
                take_over_adc();
        apply_row(0);
    }
    run((uint64_t)(flush_ms * freq / 1000), (uint64_t)(max_ms * freq / 1000));
    if (inputs && ticks_done < n_rows)
        die(3, "the firmware stopped before every tick was made", NULL);
    write_outputs(ticks_path, uart_path);
    if (marks_out)
        fclose(marks_out);
    return 0;
}
