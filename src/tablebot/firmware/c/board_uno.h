/* Board support: Arduino Uno (ATmega328P, 16 MHz) with an Arduino Motor Shield Rev3 (L298P).
 *
 * Channel A: direction D12 = PB4, PWM D3 = PD3 (OC2B), brake D9 = PB1.
 * Channel B: direction D13 = PB5, PWM D11 = PB3 (OC2A), brake D8 = PB0.
 * Brakes are held low (released); direction high = positive speed. Timer2 runs fast PWM at
 * 16 MHz / 64 / 256 = 976 Hz; speed s (0..8) is duty s/8. The trace goes out on USART0.
 */
#ifndef TB_BOARD_UNO_H
#define TB_BOARD_UNO_H

#include <avr/io.h>

#define TB_UDR UDR0
#define TB_UCSRB UCSR0B
#define TB_UDRIE UDRIE0
#define TB_UDRE_vect USART_UDRE_vect

static inline void tb_uart_init(uint16_t ubrr)
{
    UBRR0 = ubrr;
    UCSR0A = 1 << U2X0;
    UCSR0C = (1 << UCSZ01) | (1 << UCSZ00); /* 8N1 */
    UCSR0B = 1 << TXEN0;
}

/* Duty of speed s in 0..8: s/8 of 255 (8 -> 255, full on). */
static inline uint8_t uno_duty(uint8_t s)
{
    return (uint8_t)((s << 5) - (s >> 3));
}

static inline void uno_motors_init(void)
{
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB3) | (1 << PB4) | (1 << PB5);
    DDRD |= 1 << PD3;
    PORTB &= (uint8_t)~((1 << PB0) | (1 << PB1) | (1 << PB3));
    PORTD &= (uint8_t)~(1 << PD3);
    TCCR2A = (1 << WGM21) | (1 << WGM20); /* fast PWM, outputs disconnected until used */
    TCCR2B = 1 << CS22;                   /* clk / 64 */
}

/* Speed 0 disconnects the PWM output and holds the pin low: fast PWM at OCR = 0 still pulses. */
static inline void uno_motor_a(int8_t v)
{
    uint8_t s = (uint8_t)(v < 0 ? -v : v);
    if (v < 0)
        PORTB &= (uint8_t)~(1 << PB4);
    else
        PORTB |= 1 << PB4;
    if (s == 0) {
        TCCR2A &= (uint8_t)~(1 << COM2B1);
    } else {
        OCR2B = uno_duty(s);
        TCCR2A |= 1 << COM2B1;
    }
}

static inline void uno_motor_b(int8_t v)
{
    uint8_t s = (uint8_t)(v < 0 ? -v : v);
    if (v < 0)
        PORTB &= (uint8_t)~(1 << PB5);
    else
        PORTB |= 1 << PB5;
    if (s == 0) {
        TCCR2A &= (uint8_t)~(1 << COM2A1);
    } else {
        OCR2A = uno_duty(s);
        TCCR2A |= 1 << COM2A1;
    }
}

static inline void tb_board_init(void)
{
    /* INT0/INT1 (D2, D3) stay disabled; edge mode instead of the default low-level mode keeps
     * simavr 1.6 from polling a low D2/D3 every cycle. No effect on the hardware. */
    EICRA = (1 << ISC10) | (1 << ISC00);
    uno_motors_init();
}

#endif
