/* Board support: ftDuino (ATmega32U4, 16 MHz); pin map from the public Ftduino library
 * (harbaum/ftduino, ftduino/libraries/Ftduino/Ftduino.cpp).
 *
 * Inputs I1..I8 are read by the ADC (I1..I4 = ADC4..7, I5..I8 = ADC8..11) with the pull-up of
 * the input being read switched in by a CD4051 (INH = PC6, A = PF0, B = PF1, C = PD5). A
 * background ADC interrupt scans the used inputs (two conversions each, the first one settles);
 * the tick samples the latest results.
 * Outputs O1..O8 are two daisy-chained MC33879 drivers on SPI (/SS = PB0, SCK = PB1,
 * MOSI = PB2, EN = PE6). A background SPI interrupt sends one of 8 PWM slots per 32-bit word,
 * so speed s (0..8) is on in s of 8 slots (125 kHz SPI: about 490 Hz PWM).
 * The trace goes out on USART1 (TXD1 = PD3 = the C2 terminal).
 */
#ifndef TB_BOARD_FTDUINO_H
#define TB_BOARD_FTDUINO_H

#include <avr/interrupt.h>
#include <avr/io.h>

#define TB_UDR UDR1
#define TB_UCSRB UCSR1B
#define TB_UDRIE UDRIE1
#define TB_UDRE_vect USART1_UDRE_vect

static inline void tb_uart_init(uint16_t ubrr)
{
    UBRR1 = ubrr;
    UCSR1A = 1 << U2X1;
    UCSR1C = (1 << UCSZ11) | (1 << UCSZ10); /* 8N1 */
    UCSR1B = 1 << TXEN1;
}

/* --- outputs: PWM slots refreshed over SPI ------------------------------------------------ */

static volatile uint16_t ft_slot[8]; /* driver bits per PWM slot: O1..O4 high byte */
static uint8_t ft_spi_state;
static uint16_t ft_spi_word;

ISR(SPI_STC_vect)
{
    uint8_t s = ft_spi_state;
    if (!(s & 3)) {
        PORTB |= 1 << PB0; /* /SS pulse latches the last 32 bits into both drivers */
        PORTB &= (uint8_t)~(1 << PB0);
        ft_spi_word = ft_slot[(s >> 2) & 7];
    }
    /* per driver: a zero byte (no open-load detection), then its output on/off byte */
    SPDR = (s & 1) ? ((s & 2) ? (uint8_t)(ft_spi_word >> 8) : (uint8_t)ft_spi_word) : 0;
    ft_spi_state = (uint8_t)((s + 1) & 31);
}

/* Put `on` into the first `level` slots and clear `all` in the others. */
static void ft_set(uint16_t all, uint16_t on, uint8_t level)
{
    uint8_t i;
    for (i = 0; i < 8; i++)
        ft_slot[i] = (uint16_t)((ft_slot[i] & (uint16_t)~all) | (i < level ? on : 0));
}

static inline void ft_outputs_init(void)
{
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB2) | (1 << PB7);
    PORTB |= 1 << PB0;
    PORTB &= (uint8_t)~(1 << PB7); /* no PWM on the driver's IN6 */
    DDRE |= 1 << PE6;
    PORTE |= 1 << PE6; /* drivers awake */
    SPCR = (1 << SPIE) | (1 << SPE) | (1 << MSTR) | (1 << CPHA) | (1 << SPR1) | (1 << SPR0); /* mode 1, 125 kHz */
    ft_spi_state = 0;
    SPDR = 0; /* the first transfer starts the interrupt chain */
}

/* --- inputs: ADC scan with the CD4051 pull-up ------------------------------------------- */

static volatile uint8_t ft_inputs; /* bit i: input I(i+1) reads below the threshold */

#if TB_FT_N_CHANNELS > 0
static uint8_t ft_adc_next, ft_adc_phase;

static void ft_adc_start(uint8_t ch)
{
    PORTC &= (uint8_t)~(1 << PC6); /* CD4051 on: pull-up of input ch */
    if (ch & 1) PORTF |= 1 << PF0; else PORTF &= (uint8_t)~(1 << PF0);
    if (ch & 2) PORTF |= 1 << PF1; else PORTF &= (uint8_t)~(1 << PF1);
    if (ch & 4) PORTD |= 1 << PD5; else PORTD &= (uint8_t)~(1 << PD5);
    if (ch < 4) {
        ADMUX = (1 << REFS0) | (1 << MUX2) | (ch & 3); /* ADC4..ADC7 */
        ADCSRB = 0;
    } else {
        ADMUX = (1 << REFS0) | (ch & 3); /* ADC8..ADC11 */
        ADCSRB = 1 << MUX5;
    }
    ADCSRA |= 1 << ADSC;
}

static inline void ft_inputs_init(void)
{
    DDRC |= 1 << PC6;
    PORTC |= 1 << PC6;
    DDRF |= (1 << PF0) | (1 << PF1);
    DDRD |= 1 << PD5;
    DIDR0 = (1 << ADC7D) | (1 << ADC6D) | (1 << ADC5D) | (1 << ADC4D);
    DIDR2 = (1 << ADC11D) | (1 << ADC10D) | (1 << ADC9D) | (1 << ADC8D);
    ADCSRA = (1 << ADEN) | (1 << ADIE) | (1 << ADPS2) | (1 << ADPS1) | (1 << ADPS0); /* /128 */
}

static const uint8_t ft_channels[TB_FT_N_CHANNELS] = TB_FT_CHANNELS;

ISR(ADC_vect)
{
    if (ft_adc_phase) {
        uint8_t bit = (uint8_t)(1 << ft_channels[ft_adc_next]);
        if (ADC < TB_FT_THRESHOLD)
            ft_inputs |= bit;
        else
            ft_inputs &= (uint8_t)~bit;
        ft_adc_phase = 0;
        if (++ft_adc_next == TB_FT_N_CHANNELS)
            ft_adc_next = 0;
        ft_adc_start(ft_channels[ft_adc_next]);
    } else {
        ft_adc_phase = 1; /* the first conversion after switching settles; take the second */
        ADCSRA |= 1 << ADSC;
    }
}
#endif

static inline void tb_board_init(void)
{
    ft_outputs_init();
#if TB_FT_N_CHANNELS > 0
    ft_inputs_init();
    ft_adc_start(ft_channels[0]);
#endif
}

#endif
