#include "lowlevel/curve.h"

#include "lowlevel/fixmath.h"
#include "lowlevel/pgm.h"
#include "lowlevel/scratch.h"

#include <stddef.h>
#include <string.h>

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the walker reads the high word of int64");

// Size on the ATmega328P: every 64-bit addition, shift or product is a library call wrapped in
// long register moves, and every Num operation a call sequence. So these operations are written
// once, in the out-of-line helpers below (the sample step, the 64-bit sums of add_q40 and the
// signed product of mul_shift in assembly: no 64-bit library routine is left), the axes are
// loops, arrays are copied with memcpy (a byte loop, where four-byte moves are unrolled), and the
// walker's small fields come first (a field within 63 bytes of the object is reached by
// displacement).

namespace ll {
namespace {

constexpr int32_t kOneQ29 = 1l << 29;
constexpr uint32_t kTurnQ29 = 2ul * kPiQ29;
// Pieces of an arc are at most 21.5 degrees (their cubic is within 7e-8 R of the ellipse) and at
// most this many ticks long, so that N <= 4096 samples keep the forward-difference error below
// 0.02 tick.
constexpr uint32_t kMaxPieceTicks = 2000;

// The fewest pieces that keep a helix' rise within kMaxPieceTicks a piece (w moves dw / n
// linearly; 1 on a curve of two axes). A steep helix would otherwise get pieces of 2^16
// samples, whose 16-bit count wraps: its rise was lost.
__attribute__((noinline)) uint32_t rise_pieces(const CurveWalker::Ends& e) {
    return div32_16(abs32(e.end[2] - e.start[2]), kMaxPieceTicks) + 1;
}

#if defined(__AVR__)
// floor(a b / 2^s) for s <= 32 (mul_q30: s = 30), the result within 32 bits. The unsigned product
// of fixmath's multiplier (__ll_mul32, its own register convention) made signed (a negative
// factor counts as the unsigned one less 2^32: the other factor is taken off the high word), then
// the bits s to s + 31 of the 64-bit word, whole bytes by moves first; bits shifted in at the top
// never reach the low word for s <= 32. For s = 30 (mul_q30, 16 products a piece of an arc), bytes
// 3 to 7 shifted left twice: 95 cycles less than three moves and six shifts right. In assembly:
// avr-gcc would call its 64-bit product and shift routines, which nothing else in the image needs,
// and it saves more registers.
extern "C" int32_t ll_curve_mul_shift(int32_t a, int32_t b, uint8_t s);
extern "C" int32_t ll_curve_mul_q30(int32_t a, int32_t b);
asm(".section .text.ll_curve_mul_shift,\"ax\",@progbits\n"
    ".global ll_curve_mul_q30\n"
    "ll_curve_mul_q30:\n"
    "ldi  r26, 30\n"
    "rjmp .Lll_curve_mul\n"
    ".global ll_curve_mul_shift\n"
    "ll_curve_mul_shift:\n"
    "mov  r26, r16\n"
    ".Lll_curve_mul:\n"
    "push r14\n"
    "push r15\n"
    "push r16\n"
    "push r17\n"
    "push r26\n" // s
    "clr  r26\n" // the correction: (a < 0 ? b : 0) + (b < 0 ? a : 0)
    "clr  r27\n"
    "movw r30, r26\n"
    "sbrs r25, 7\n"
    "rjmp 2f\n"
    "movw r26, r18\n"
    "movw r30, r20\n"
    "2:\n"
    "sbrs r21, 7\n"
    "rjmp 3f\n"
    "add  r26, r22\n"
    "adc  r27, r23\n"
    "adc  r30, r24\n"
    "adc  r31, r25\n"
    "3:\n"
    "push r26\n"
    "push r27\n"
    "push r30\n"
    "push r31\n"
    "call __ll_mul32\n" // (r22..r25, r18..r21) = the product's (high, low) words
    "pop  r31\n"
    "pop  r30\n"
    "pop  r27\n"
    "pop  r26\n"
    "sub  r22, r26\n"
    "sbc  r23, r27\n"
    "sbc  r24, r30\n"
    "sbc  r25, r31\n"
    "pop  r26\n"
    "pop  r17\n"
    "pop  r16\n"
    "pop  r15\n"
    "pop  r14\n"
    "cpi  r26, 30\n" // mul_q30: bytes 3 to 7 shifted left twice (s counts to 32)
    "brne 4f\n"
    "8:\n"
    "lsl  r21\n"
    "rol  r22\n"
    "rol  r23\n"
    "rol  r24\n"
    "rol  r25\n"
    "inc  r26\n"
    "sbrc r26, 0\n"
    "rjmp 8b\n"
    "ret\n"
    "4:\n"
    "subi r26, 8\n"
    "brcs 5f\n"
    "mov  r18, r19\n"
    "mov  r19, r20\n"
    "mov  r20, r21\n"
    "mov  r21, r22\n"
    "mov  r22, r23\n"
    "mov  r23, r24\n"
    "mov  r24, r25\n"
    "rjmp 4b\n"
    "5:\n"
    "subi r26, -8\n" // the bits left, s mod 8
    "breq 7f\n"
    "6:\n"
    "lsr  r25\n"
    "ror  r24\n"
    "ror  r23\n"
    "ror  r22\n"
    "ror  r21\n"
    "ror  r20\n"
    "ror  r19\n"
    "ror  r18\n"
    "dec  r26\n"
    "brne 6b\n"
    "7:\n"
    "movw r22, r18\n"
    "movw r24, r20\n"
    "ret\n"
    // lerp(x, y, a) = x + mul_shift(y - x, a, 20): x in r22..r25, y in r18..r21, a in r14..r17.
    ".global ll_curve_lerp\n"
    "ll_curve_lerp:\n"
    "push r22\n"
    "push r23\n"
    "push r24\n"
    "push r25\n"
    "sub  r18, r22\n"
    "sbc  r19, r23\n"
    "sbc  r20, r24\n"
    "sbc  r21, r25\n"
    "movw r22, r18\n"
    "movw r24, r20\n"
    "movw r18, r14\n"
    "movw r20, r16\n"
    "ldi  r26, 20\n"
    "rcall .Lll_curve_mul\n"
    "pop  r21\n"
    "pop  r20\n"
    "pop  r19\n"
    "pop  r18\n"
    "add  r22, r18\n"
    "adc  r23, r19\n"
    "adc  r24, r20\n"
    "adc  r25, r21\n"
    "ret\n"
    ".text\n");
extern "C" int32_t ll_curve_lerp(int32_t x, int32_t y, uint32_t a_q20);

inline int32_t mul_shift(int32_t a, int32_t b, uint8_t s) {
    return ll_curve_mul_shift(a, b, s);
}

// (a b) >> 30: products of Q30 factors, and Q8 coordinates times Q30 factors.
inline int32_t mul_q30(int32_t a, int32_t b) {
    return ll_curve_mul_q30(a, b);
}
#else
// floor(a b / 2^s), the result within 32 bits.
__attribute__((noinline)) int32_t mul_shift(int32_t a, int32_t b, uint8_t s) {
    return static_cast<int32_t>((static_cast<int64_t>(a) * b) >> s);
}

// (a b) >> 30: products of Q30 factors, and Q8 coordinates times Q30 factors.
__attribute__((noinline)) int32_t mul_q30(int32_t a, int32_t b) {
    return mul_shift(a, b, 30);
}
#endif

// avr-gcc's -mcall-prologues saves and restores registers through the shared
// __prologue_saves__ / __epilogue_restores__ only when the saved ones form a single run ending at
// r17; otherwise each function pushes and pops them one by one (and sets up its frame in line).
// These empty statements mark the gap of a function's run as used: a few bytes of stack for
// 40 to 80 bytes of code.
__attribute__((always_inline)) inline void save_run_from_r8() {
#if defined(__AVR__)
    asm volatile("" ::: "r8", "r9");
#endif
}
__attribute__((always_inline)) inline void save_run_to_r17() {
#if defined(__AVR__)
    asm volatile("" ::: "r16", "r17");
#endif
}

// Forward differences in place: (p0, p1, p2, p3) -> (p0, p1 - p0, p2 - 2 p1 + p0, p3 - 3 p2 + ...).
#if defined(__AVR__)
// In assembly: passes of 3, 2 and 1 subtractions q[j] -= q[j - 1] from j = 3 down, byte by byte
// (avr-gcc unrolls the loops into 32-bit loads and stores).
extern "C" void ll_curve_differences(int32_t q[4]);
asm(".section .text.ll_curve_differences,\"ax\",@progbits\n"
    ".global ll_curve_differences\n"
    "ll_curve_differences:\n"
    "ldi  r18, 3\n" // subtractions in this pass
    "1:\n"
    "movw r30, r24\n"
    "adiw r30, 8\n" // Z = &q[j - 1], j = 3
    "mov  r19, r18\n"
    "2:\n"
    "ldi  r20, 4\n"
    "clc\n"
    "3:\n"
    "ld   r21, Z+\n"
    "ldd  r22, Z+3\n"
    "sbc  r22, r21\n"
    "std  Z+3, r22\n"
    "dec  r20\n"
    "brne 3b\n"
    "sbiw r30, 8\n" // j - 1
    "dec  r19\n"
    "brne 2b\n"
    "dec  r18\n"
    "brne 1b\n"
    "ret\n"
    ".text\n");
inline void differences(int32_t q[4]) {
    ll_curve_differences(q);
}
#else
void differences(int32_t q[4]) {
    for (uint8_t i = 1; i < 4; ++i) {
        for (uint8_t j = 3; j >= i; --j) q[j] -= q[j - 1];
    }
}
#endif

// Taylor coefficients (Q30) of cos x, sin x / x and tan x / x as polynomials in x^2, with the
// signs of cos and sin taken by evaluating at -x^2. For |x| <= 0.4 rad the first term left out is
// below 2^-31.
const uint32_t kSeriesQ30[3][5] LL_PROGMEM = {
    {1073741824, 536870912, 44739243, 1491308, 26631},       // 1, 1/2, 1/24, 1/720, 1/40320
    {1073741824, 178956971, 8947849, 213044, 2959},          // 1, 1/6, 1/120, 1/5040, 1/362880
    {1073741824, 357913941, 143165577, 57947971, 23482185}}; // 1, 1/3, 2/15, 17/315, 62/2835

// Series `which` of kSeriesQ30 at y (Horner's rule), Q30.
int32_t series(uint8_t which, int32_t y) {
    save_run_to_r17();
    int32_t r = 0;
    for (uint8_t i = 5; i-- > 0;) {
        r = static_cast<int32_t>(flash_read_u32(&kSeriesQ30[which][i])) + mul_q30(r, y);
    }
    return r;
}

// rot = (cos h, sin h) for |h| <= 0.4 rad, Q30.
void rotation(int32_t h, int32_t rot[2]) {
    save_run_to_r17();
    int32_t y = -mul_q30(h, h);
    rot[0] = series(0, y);
    rot[1] = mul_q30(h, series(1, y));
}

// v = (cos t, sin t) turned by the angle of rot, Q30.
void rotate(int32_t v[2], const int32_t rot[2]) {
    save_run_from_r8();
    int32_t c = mul_q30(v[0], rot[0]) - mul_q30(v[1], rot[1]);
    v[1] = mul_q30(v[1], rot[0]) + mul_q30(v[0], rot[1]);
    v[0] = c;
}

// sum = sqrt(q0^2 + ... + q(n-1)^2) (written, not returned: no copies through the frames).
__attribute__((noinline)) void root_sum_squares(const Num* q, uint8_t n, Num& sum) {
    sum.m = 0;
    for (uint8_t i = 0; i < n; ++i) {
        Num t = q[i];
        sum.add(t.mul(q[i]));
    }
    sum.sqrt();
}

// out[i] = q[i] / |q| for the n components of q, `bits` fraction bits, negated where bit i of
// `neg` is set; 0 for q = 0 (a quotient by zero is zero). The q are overwritten.
__attribute__((noinline)) void unit_vector(Num* q, uint8_t n, uint8_t neg, uint8_t bits,
                                           int32_t* out) {
    Num norm;
    root_sum_squares(q, n, norm);
    for (uint8_t i = 0, bit = 1; i < n; ++i, bit = static_cast<uint8_t>(bit << 1)) {
        uint32_t u = q[i].div(norm).shift(static_cast<int8_t>(bits)).u32(); // (q is spent)
        if (u > (1ul << bits)) u = 1ul << bits;
        out[i] = neg & bit ? -static_cast<int32_t>(u) : static_cast<int32_t>(u);
    }
}

// The larger of an ellipse's semi-axes.
__attribute__((noinline)) uint32_t larger(const uint32_t r[2]) {
    return r[0] > r[1] ? r[0] : r[1];
}

// q = (|v0|, |v1|, third); returns the signs of v0 and v1 (bits 0 and 1).
__attribute__((noinline)) uint8_t components(const int32_t v[2], const Num& third, Num q[3]) {
    q[2] = third;
    uint8_t neg = 0;
    for (uint8_t i = 2; i-- > 0;) {
        neg = static_cast<uint8_t>(neg << 1);
        if (v[i] < 0) ++neg;
        q[i].set(abs32(v[i]));
    }
    return neg;
}

// ellipse_direction() of the vector v, overwritten with (cos t, sin t), Q30. In place: no
// vector and no result in the callers' frames (ellipse_direction() is on the deepest stack of a
// G-code line).
__attribute__((noinline)) void direction_of(int32_t v[2], const uint32_t radii[2]) {
    Num q[3];
    const uint8_t neg = components(v, Num{}, q); // (v is read here, then only written)
    for (uint8_t k = 0; k < 2; ++k) q[k].div(radii[k]);
    unit_vector(q, 2, neg, 30, v);
}

// |sweep| in (0, 2 pi] from the direction dir[0] to dir[1] (Q30), clockwise or not (radians x
// 2^29): a closed arc is a full turn. The difference of the angles (in (-pi, pi]) is taken
// modulo 2^32, where the result (below 2^32) is exact; clockwise, from dir[1] to dir[0].
__attribute__((noinline)) uint32_t sweep_of(const int32_t dir[2][2], bool clockwise) {
    const int32_t* from = dir[clockwise];
    const int32_t* to = dir[!clockwise];
    const int32_t a0 = atan2_q29(from[1], from[0]);
    const int32_t a1 = atan2_q29(to[1], to[0]);
    const uint32_t d = static_cast<uint32_t>(a1) - static_cast<uint32_t>(a0);
    return a1 > a0 ? d : d + kTurnQ29;
}

// Directions (cos t, sin t) of an arc's start and end (`ends`: the two points in a row, as in
// CurveParams and CurveWalker::Ends) seen from its centre in the ellipse's scale (Q30), and
// |sweep| without the extra turns (radians x 2^29, never 0); 0 for a null radius.
__attribute__((noinline)) uint32_t arc_directions(const int32_t ends[2][2], const int32_t centre[2],
                                                  const uint32_t radii[2], bool clockwise,
                                                  int32_t dir[2][2]) {
    if (radii[0] == 0 || radii[1] == 0) return 0;
    const int32_t* p = ends[0];
    int32_t* v = dir[0];
    for (uint8_t i = 0; i < 4; ++i) {
        // centre[i & 1] as a pointer bumped on odd i (an indexed 32-bit load took 24 B more)
        const int32_t* c = centre;
        if (i & 1) ++c;
        *v++ = *p++ - *c;
    }
    direction_of(dir[0], radii);
    direction_of(dir[1], radii);
    return sweep_of(dir, clockwise);
}

// The start and end points of a curve as a row of two (consecutive fields, pinned here).
inline const int32_t (*ends_of(const CurveParams& c))[2] {
    static_assert(offsetof(CurveParams, end_um) == offsetof(CurveParams, start_um) + 8,
                  "start and end in a row");
    return &c.start_um;
}
inline const int32_t (*ends_of(const CurveWalker::Ends& e))[2] {
    static_assert(offsetof(CurveWalker::Ends, end_q8) == offsetof(CurveWalker::Ends, start_q8) + 8,
                  "start and end in a row");
    return &e.start_q8;
}

// One sample of a cubic by forward differencing: f += d1, d1 += d2, d2 += d3 (v = f, d1, d2, d3).
inline void fd_step(int64_t v[4]) {
#if defined(__AVR__)
    // Byte by byte in place, each sum with the next value's old bytes (8 bytes on), a whole sum
    // a turn: 180 cycles and 72 bytes (four bytes a turn: 200 cycles and 46 bytes), where
    // avr-gcc calls __adddi3 three times through long register moves.
    uint8_t n, x, y;
    asm volatile("ldi  %[n], 3\n"
                 "1:\n\t"
                 "clc\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "ld   %[x], Z\n\t"
                 "ldd  %[y], Z+8\n\t"
                 "adc  %[x], %[y]\n\t"
                 "st   Z+, %[x]\n\t"
                 "dec  %[n]\n\t"
                 "brne 1b"
                 : "+z"(v), [n] "=&d"(n), [x] "=&r"(x), [y] "=&r"(y)
                 :
                 : "memory");
#else
    v[0] += v[1];
    v[1] += v[2];
    v[2] += v[3];
#endif
}

// acc += x / 2^s in Q40 for x in Q8 (s <= 36): exact for s <= 32, floored beyond.
#if defined(__AVR__)
// In assembly: the addend in two words (x, 0) shifted together (whole bytes by moves, the rest
// bit by bit: a piece's shifts reach 3 m bits), then added byte by byte. avr-gcc
// would call the 64-bit shift and sum routines of its library, which nothing else in the image
// needs.
extern "C" void ll_curve_add_q40(int64_t& acc, int32_t x, uint8_t s);
asm(".section .text.ll_curve_add_q40,\"ax\",@progbits\n"
    ".global ll_curve_add_q40\n"
    "ll_curve_add_q40:\n"
    "mov  r30, r18\n" // s
    "movw r26, r24\n" // X = &acc
    "movw r24, r22\n" // (r22..r25, r18..r21) = (x, 0)
    "movw r22, r20\n"
    "clr  r18\n"
    "clr  r19\n"
    "movw r20, r18\n"
    "0:\n" // whole bytes by moves first
    "subi r30, 8\n"
    "brcs 3f\n"
    "mov  r18, r19\n"
    "mov  r19, r20\n"
    "mov  r20, r21\n"
    "mov  r21, r22\n"
    "mov  r22, r23\n"
    "mov  r23, r24\n"
    "mov  r24, r25\n"
    "lsl  r25\n"
    "sbc  r25, r25\n"
    "rjmp 0b\n"
    "3:\n"
    "subi r30, -8\n" // the bits left, s mod 8
    "breq 2f\n"
    "1:\n"
    "asr  r25\n"
    "ror  r24\n"
    "ror  r23\n"
    "ror  r22\n"
    "ror  r21\n"
    "ror  r20\n"
    "ror  r19\n"
    "ror  r18\n"
    "dec  r30\n"
    "brne 1b\n"
    "2:\n"
    "ld   r0, X\n"
    "add  r0, r18\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r19\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r20\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r21\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r22\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r23\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r24\n"
    "st   X+, r0\n"
    "ld   r0, X\n"
    "adc  r0, r25\n"
    "st   X, r0\n"
    "ret\n"
    ".text\n");
inline void add_q40(int64_t& acc, int32_t x, uint8_t s) {
    ll_curve_add_q40(acc, x, s);
}
#else
__attribute__((noinline)) void add_q40(int64_t& acc, int32_t x, uint8_t s) {
    acc += (static_cast<int64_t>(x) << 32) >> s;
}
#endif

// x + (y - x) a = (x (2^20 - a) + y a) / 2^20 (floored), a in [0, 1] as Q20: one step of de
// Casteljau's algorithm, exact (y - x fits in 32 bits: the points are within 2^30 of zero).
#if defined(__AVR__)
inline int32_t lerp(int32_t x, int32_t y, uint32_t a_q20) {
    return ll_curve_lerp(x, y, a_q20); // (in the assembly of mul_shift)
}
#else
__attribute__((noinline)) int32_t lerp(int32_t x, int32_t y, uint32_t a_q20) {
    return x + mul_shift(y - x, static_cast<int32_t>(a_q20), 20);
}
#endif

// x + 2 pi (radians x 2^29), out of line: in a loop, avr-gcc would make the sum of the turns a
// 64-bit product, a library routine that nothing else in the image needs.
__attribute__((noinline)) int64_t add_turn(int64_t x) {
    return x + kTurnQ29;
}

// On the ellipse of semi-axes r at the direction v = (cos t, sin t) (Q30): the tangent
// (-ru sin t, rv cos t), reversed with `back`, and the radius (ru cos t, rv sin t) (the point
// seen from the centre, and -P''). The walker's pieces and the planner's track both use it.
__attribute__((noinline)) void ellipse_at(const int32_t r[2], const int32_t v[2], bool back,
                                          int32_t tangent[2], int32_t radius[2]) {
    for (uint8_t i = 0; i < 2; ++i) {
        int32_t a = v[1 - i];
        if (i == back) a = -a;
        tangent[i] = mul_q30(r[i], a);
        radius[i] = mul_q30(r[i], v[i]);
    }
}

} // namespace

void ellipse_direction(int32_t x_q8, int32_t y_q8, const uint32_t radii_q8[2], int32_t& c,
                       int32_t& s) {
    int32_t u[2] = {x_q8, y_q8};
    direction_of(u, radii_q8);
    c = u[0];
    s = u[1];
}

int64_t arc_sweep_q29(int32_t c0, int32_t s0, int32_t c1, int32_t s1, bool clockwise,
                      uint8_t turns) {
    const int32_t dir[2][2] = {{c0, s0}, {c1, s1}};
    int64_t sweep = sweep_of(dir, clockwise);
    while (turns--) sweep = add_turn(sweep);
    return clockwise ? -sweep : sweep;
}

void CurveWalker::begin(const Ends& e, uint16_t pieces, uint8_t kind) {
    piece_count_ = pieces_ = pieces;
    static_assert(offsetof(Ends, end) == offsetof(Ends, start) + sizeof(pos), "in a row");
    memcpy(pos, e.start, sizeof(pos) + sizeof(end_)); // and end_ (curve.h)
    // (The start of the curve in the plane, prev_q8_[0..1], is set by next_piece().)
    // w moves linearly along the curve (a helix); without it, only u and v are walked.
    prev_q8_[2] = w0_q8_ = e.start[2] * 256;
    dw_q8_ = e.end[2] * 256 - w0_q8_;
    axes_ = dw_q8_ ? 3 : 2;
    kind_ = kind;
    left_ = 0;
}

__attribute__((always_inline)) inline void CurveWalker::start_piece(Piece& g) {
    // The cubic from prev_q8_ (p0) to p3 whose control points are p0 + arm0 / 3 and
    // p3 - arm3 / 3, ticks x 256: relative to p0, c1 t + c2 t^2 + c3 t^3 with c1 = arm0,
    // c3 = arm0 + arm3 - 2 D and c2 = D - c1 - c3, D = p3 - p0 (in place of arm0, p3 and arm3).
    memset(fd_, 0, sizeof(fd_));
    uint32_t bound = 0; // largest axis speed over the piece, ticks x 256 per unit of t
    // (w's coefficients are zero on a curve of two axes, whose w never moves: its differences
    // stay the zeros above, and next() never reads them.)
    const uint8_t axes = axes_;
    for (uint8_t a = 0; a < axes; ++a) {
        // f: where the piece starts, ticks x 2^40 (the points are within 2^22 ticks of zero).
        // (Plus half a tick: next() rounds by taking the ticks' bits alone.)
        const int32_t f = prev_q8_[a] + 128;
        memcpy(reinterpret_cast<uint8_t*>(fd_[a]) + 4, &f, 4);
        const int32_t d = g.v[kP3][a] - prev_q8_[a];
        prev_q8_[a] = g.v[kP3][a];
        const int32_t c1 = g.v[kArm0][a];
        const int32_t c3 = c1 + g.v[kArm3][a] - 2 * d;
        const int32_t c2 = d - c1 - c3;
        g.v[kP3][a] = c2;
        g.v[kArm3][a] = c3;
        const uint32_t a2 = abs32(c3);
        const uint32_t b = abs32(c1) + 2 * (abs32(c2) + a2) + a2;
        if (b > bound) bound = b;
    }
    // N = 2^m > bound (ticks): at most one tick per sample and axis.
    uint8_t m = 0;
    uint16_t samples = 1;
    for (uint32_t b = bound >> 8; b != 0; b >>= 1) {
        ++m;
        samples = static_cast<uint16_t>(samples << 1);
    }
    left_ = samples;
    for (uint8_t a = 0; a < axes; ++a) {
        int64_t* v = fd_[a];
        // The differences at t = 0 for the step 1/N: c1/N + c2/N^2 + c3/N^3,
        // 2 c2/N^2 + 6 c3/N^3, 6 c3/N^3, term by term (c_pw / N^pw into the differences 1 to pw).
        uint8_t sh = m;
        for (uint8_t pw = 1; pw <= 3; ++pw, sh = static_cast<uint8_t>(sh + m)) {
            for (uint8_t i = 1; i <= pw; ++i) {
                // (n c below 2^31)
                const uint8_t n = i == 1 ? 1 : pw == 2 ? 2 : 6;
                add_q40(v[i], g.v[pw - 1][a] * n, sh);
            }
        }
    }
}

__attribute__((always_inline)) inline void
CurveWalker::arc_at(const int32_t dir[2], int32_t point[2], int32_t arm[2]) const {
    // X = cu + ru cos t, Y = cv + rv sin t; the arm is the tangent (-ru sin t, rv cos t) times
    // 4 tan(h/4).
    ellipse_at(reinterpret_cast<const int32_t*>(a_.radii), dir, false, arm, point);
    for (uint8_t k = 0; k < 2; ++k) {
        point[k] += a_.centre[k];
        arm[k] = mul_q30(arm[k], a_.arm);
    }
}

bool CurveWalker::arc(const Ends& e, const int32_t centre_q8[2], const uint32_t radii_q8[2],
                      bool clockwise, uint8_t turns) {
    kind_ = 0;
    memcpy(a_.centre, centre_q8, sizeof(a_.centre));
    memcpy(a_.radii, radii_q8, sizeof(a_.radii));
    // Directions of the start and end points (their projections on the curve), and the sweep
    // with the extra turns, radians x 2^20 (below 2^31 for 255 turns).
    uint32_t mag = arc_directions(ends_of(e), a_.centre, a_.radii, clockwise, a_.dir);
    if (mag == 0) return false; // a null radius
    mag = (mag >> 9) + turns * (kTurnQ29 >> 9);
    // Pieces: at most 3 x 2^17 / 2^20 rad (21.5 degrees), kMaxPieceTicks long (sweep x radius
    // ticks) and rising at most as much (rise_pieces()).
    uint32_t rmax = larger(a_.radii) >> 8;
    // (x / 3 for x = mag / 2^17 below 2^14, by its reciprocal: a division is a library call.)
    uint32_t n = ((mag >> 17) * 21846ul >> 16) + 1u;
    uint32_t by_length = Num(mag, -20).mul(rmax + 1).div(kMaxPieceTicks).u32() + 1;
    if (by_length > n) n = by_length;
    by_length = rise_pieces(e);
    if (by_length > n) n = by_length;
    if (n > 0xFFFF) return false;
    // Piece angle h, Q30 (at most 21.5 degrees, so the series apply), and 3 x the arm of its
    // cubic per unit of radius, 4 tan(h/4).
    int32_t h = static_cast<int32_t>(div_frac(mag, n, 10));
    if (clockwise) h = -h;
    rotation(h, a_.rot);
    int32_t x = h >> 2;
    a_.arm = 4 * mul_q30(x, series(2, mul_q30(x, x)));
    begin(e, static_cast<uint16_t>(n), 1);
    return true;
}

void CurveWalker::bezier_at(uint16_t at, int32_t point[2], int32_t arm[2]) const {
    // At a = at / 2^j (Q20): B(a) (with `point`) and B'(a) / 2^j, 3 x the arm of the piece that
    // starts or ends there (ticks x 256), by de Casteljau's algorithm: every value stays within
    // the control points' hull.
    const uint32_t a_q20 = static_cast<uint32_t>(at) << (20 - log_pieces_);
    for (uint8_t k = 0; k < 2; ++k) {
        int32_t q[4];
        memcpy(q, pts_[k], sizeof(q));
        for (uint8_t n = 3; n > 1; --n) {
            for (uint8_t i = 0; i < n; ++i) q[i] = lerp(q[i], q[i + 1], a_q20);
        }
        point[k] = lerp(q[0], q[1], a_q20);
        // B'(a) = 3 (q1 - q0), with q1 - q0 below 2^31 in magnitude (as the points' differences).
        int32_t d = static_cast<int32_t>(static_cast<uint32_t>(q[1]) - static_cast<uint32_t>(q[0]));
        arm[k] = mul_shift(d, 3, log_pieces_);
    }
}

bool CurveWalker::bezier(const Ends& e, const int32_t p1_q8[2], const int32_t p2_q8[2]) {
    save_run_to_r17();
    kind_ = 0;
    uint32_t bound = 0; // hodograph bound (power basis), ticks
    const int32_t* src[4] = {e.start_q8, p1_q8, p2_q8, e.end_q8};
    for (uint8_t k = 0; k < 2; ++k) {
        // B'(a) = 3 D1 + 6 D2 a + 3 D3 a^2 (D: the forward differences of the points, ticks).
        int32_t d[4];
        for (uint8_t i = 0; i < 4; ++i) {
            const int32_t* p = src[i]; // src[i][k], without a 16-bit byte offset counted by k
            if (k) ++p;
            d[i] = (pts_[k][i] = *p) >> 8;
        }
        differences(d);
        uint32_t b = abs32(d[2]);
        b += b + abs32(d[1]);
        b += abs32(d[3]);
        if (b > bound) bound = b;
    }
    bound *= 3;
    // 2^j pieces, each with a hodograph bound below kMaxPieceTicks (it shrinks with 2^j), and
    // as many as a helix' rise needs.
    const uint32_t need = rise_pieces(e);
    uint8_t j = 0;
    uint16_t n = 1;
    for (; bound >= kMaxPieceTicks || n < need; bound >>= 1) {
        if (j == 15) return false;
        ++j;
        n = static_cast<uint16_t>(n << 1);
    }
    log_pieces_ = j;
    begin(e, n, 2);
    return true;
}

bool CurveWalker::next_piece() {
    if (pieces_ == 0) return false;
    uint16_t index = static_cast<uint16_t>(piece_count_ - pieces_); // 0-based
    --pieces_;
    bool last = pieces_ == 0;
    // The end of the piece on the curve and 3 x its arms at both ends, ticks x 256.
    Piece g;
    int32_t *p3 = g.v[kP3], *arm0 = g.v[kArm0], *arm3 = g.v[kArm3];
    // Helix: w moves linearly (arms of a third of its move), the last piece landing exactly on
    // the end.
    const int32_t dw = dw_q8_;
    int32_t w3 = dw;
    if (!last && dw != 0) { // (w moves: a helix)
        w3 = static_cast<int32_t>(
            Num(abs32(dw)).mul(static_cast<uint32_t>(index) + 1).div(piece_count_).u32());
        if (dw < 0) w3 = -w3;
    }
    p3[2] = w3 + w0_q8_;
    arm0[2] = arm3[2] = p3[2] - prev_q8_[2];
    // The start of the piece (s = 0) and its end (s = 1): the point, overwritten at the end, and
    // the arm. An arc's direction turns by a piece between them; a Bezier part is [a, a + 1/n].
    int32_t* dir = a_.dir[0];
    for (uint8_t s = 0; s < 2; ++s) {
        static_assert(kArm0 == 0 && kArm3 == 2, "the arms at both ends");
        int32_t* arm = g.v[2 * s];
        // Where the piece starts (s = 0): the last one's end, computed the same way; the first
        // piece's, the arc at its start direction, or B(0) = P0 exactly.
        int32_t* point = s ? p3 : prev_q8_;
        if (kind_ != 1) {
            // (At a = 1 every step of de Casteljau's algorithm gives its right point exactly:
            // the last piece ends on the commanded end.)
            bezier_at(static_cast<uint16_t>(index + s), point, arm);
        } else {
            if (s) {
                rotate(dir, a_.rot);
                if (last) memcpy(dir, a_.dir[1], sizeof(a_.dir[1])); // no drift left over
            }
            arc_at(dir, point, arm);
        }
    }
    start_piece(g);
    return true;
}

bool CurveWalker::next(uint8_t& moved, uint8_t& neg) {
    // One sample: at most one tick per axis (seed §9's micro steps along the curve).
    // Past the last piece: the last step, from the rounded end of the curve to the exact target
    // (at most one tick per axis: both are within 0.71 tick of the curve's end point); once made
    // (the position is the end), no step and false.
    if (left_ == 0 && kind_ != 0 && !next_piece()) kind_ = 0; // (a piece has a sample at least)
    const bool walking = kind_ != 0;
    const uint8_t axes = axes_; // (w never moves on a curve of two axes: its end is its start)
    uint8_t bits = 0, down = 0, bit = 1;
    for (uint8_t a = 0; a < axes; ++a, bit = static_cast<uint8_t>(bit << 1)) {
        int32_t p = end_[a];
        if (walking) {
            int64_t* v = fd_[a];
            fd_step(v);
            // round(f / 2^40) from the high word of f + 2^39 (start_piece): floor(hi / 2^8).
            // The word is read from memory: avr-gcc would shift the 64 bits through a library
            // loop.
            int32_t hi;
            memcpy(&hi, reinterpret_cast<const uint8_t*>(v) + 4, 4);
            p = hi >> 8;
        }
        // Compared on the low bytes (the same whenever the two are less than 128 ticks apart):
        // a sample is at most a tick from the last, and so is the end from the last sample.
        const int8_t diff =
            static_cast<int8_t>(static_cast<uint8_t>(p) - static_cast<uint8_t>(pos[a]));
        if (diff != 0) {
            bits = static_cast<uint8_t>(bits | bit);
            if (diff < 0) down = static_cast<uint8_t>(down | bit);
            pos[a] = p;
        }
    }
    moved = bits;
    neg = down;
    if (!walking) return bits != 0;
    --left_;
    return true;
}

void CurveWalker::chord(int32_t d[3]) const {
    // d1 / 2^24 (below 2^17): bits 24 to 55 of the little-endian word.
    for (uint8_t a = 0; a < 3; ++a) {
        memcpy(&d[a], reinterpret_cast<const uint8_t*>(&fd_[a][1]) + 3, 4);
    }
}

// (Here, not in the step generator: the displacement is read in place, and the Num values are in
// this frame, not in fill_curve()'s while the walker steps below it.)
uint32_t CurveWalker::chord_q8(uint8_t timed, const uint8_t machine[3], const Num inv2[]) const {
    Num sum{};
    for (uint8_t k = 0; k < 3; ++k, timed = static_cast<uint8_t>(timed >> 1)) {
        if (!(timed & 1)) continue;
        // d1 / 2^24, ticks x 2^16 (as chord() gives it)
        int32_t d;
        memcpy(&d, reinterpret_cast<const uint8_t*>(&fd_[k][1]) + 3, 4);
        Num v(abs32(d));
        v.mul(v).mul(inv2[machine[k]]);
        sum.add(v);
    }
    // mm over 2^16 -> µm x 256: x 256000 / 2^16 = 0xFA000000 x 2^-30 (mul() would take 256000
    // as 0xFA000000 x 2^-14, then the shift)
    uint32_t len = sum.sqrt().mulc(0xFA000000ul, -30).u32();
    if (len == 0) len = 1;
    return len;
}

namespace {

// (1 - sqrt(3/5)) / 2, Q30: the outer Gauss-Legendre nodes of a panel [0, 1].
constexpr int32_t kGaussQ30 = 121012492;
// Panel width bounds, parameter units x 2^29: an ellipse's angle (the series apply up to 0.4
// rad), a Bezier's t, and the narrowest panel (a cusp: |B'| -> 0).
constexpr uint32_t kWidestArcQ29 = kPiQ29 / 8;
constexpr uint32_t kWidestBezierQ29 = kOneQ29 / 16;
constexpr uint32_t kNarrowestQ29 = kOneQ29 >> 16;

// A curve as the length integral walks it: its first and second derivatives with respect to its
// parameter, x 2^scale (scaled so that the largest coefficient has 28 bits: relative precision
// whatever the size of the curve).
struct Track {
    bool bezier;
    bool clockwise; ///< ellipse: the angle decreases
    bool w_down;    ///< w decreases along the curve
    bool w_counts;  ///< w's travel counts in the length
    union {
        struct {
            int32_t r[2];      ///< radii
            int32_t dir[2][2]; ///< (cos t, sin t) of the current point and of the end, Q30
        } e;                   ///< ellipse
        struct {
            uint32_t t;      ///< parameter of the current point, Q29
            int32_t h[3][2]; ///< B'(t) = h0 + t (h1 + t h2)
        } b;                 ///< Bezier
    };
    Num rise;      ///< |dw / dparameter|: the helix' rise
    Num rmin;      ///< Bezier: smallest radius of curvature met so far, x 2^30 (2^100: none)
    uint32_t half; ///< |P'| / |P''| / 2 at the end of the last panel, Q29 (track_length())
};

// Shifts v[0..n-1] (n >= 1) left or right so that the largest magnitude is in [2^27, 2^28); the
// shift (0 when all are zero).
#if defined(__AVR__)
// In assembly: the union of the magnitudes shifted up to its top bit counts the shift from -4
// (top bit 31), then each value is shifted in place.
extern "C" int8_t ll_curve_normalise(int32_t* v, uint8_t n);
asm(".section .text.ll_curve_normalise,\"ax\",@progbits\n"
    ".global ll_curve_normalise\n"
    "ll_curve_normalise:\n"
    "movw r30, r24\n" // Z = v
    "movw r26, r24\n" // X: v[i], then the end
    "mov  r0, r22\n"
    "clr  r18\n" // r18..r21: the union of |v[i]|
    "clr  r19\n"
    "movw r20, r18\n"
    "1:\n"
    "ld   r22, X+\n"
    "ld   r23, X+\n"
    "ld   r24, X+\n"
    "ld   r25, X+\n"
    "sbrs r25, 7\n"
    "rjmp 2f\n"
    "com  r25\n"
    "com  r24\n"
    "com  r23\n"
    "neg  r22\n"
    "sbci r23, 0xFF\n"
    "sbci r24, 0xFF\n"
    "sbci r25, 0xFF\n"
    "2:\n"
    "or   r18, r22\n"
    "or   r19, r23\n"
    "or   r20, r24\n"
    "or   r21, r25\n"
    "dec  r0\n"
    "brne 1b\n"
    "ldi  r24, 0\n"
    "mov  r22, r18\n"
    "or   r22, r19\n"
    "or   r22, r20\n"
    "or   r22, r21\n"
    "breq 9f\n"
    "ldi  r24, 0xFC\n" // -4
    "3:\n"
    "sbrc r21, 7\n"
    "rjmp 4f\n"
    "lsl  r18\n"
    "rol  r19\n"
    "rol  r20\n"
    "rol  r21\n"
    "inc  r24\n"
    "rjmp 3b\n"
    "4:\n"
    "ld   r18, Z\n"
    "ldd  r19, Z+1\n"
    "ldd  r20, Z+2\n"
    "ldd  r21, Z+3\n"
    "mov  r22, r24\n"
    "tst  r22\n"
    "breq 7f\n"
    "brmi 6f\n"
    "5:\n"
    "lsl  r18\n"
    "rol  r19\n"
    "rol  r20\n"
    "rol  r21\n"
    "dec  r22\n"
    "brne 5b\n"
    "rjmp 7f\n"
    "6:\n"
    "asr  r21\n"
    "ror  r20\n"
    "ror  r19\n"
    "ror  r18\n"
    "inc  r22\n"
    "brne 6b\n"
    "7:\n"
    "st   Z+, r18\n"
    "st   Z+, r19\n"
    "st   Z+, r20\n"
    "st   Z+, r21\n"
    "cp   r30, r26\n"
    "cpc  r31, r27\n"
    "brne 4b\n"
    "9:\n"
    "ret\n"
    ".text\n");
inline int8_t normalise(int32_t* v, uint8_t n) {
    return ll_curve_normalise(v, n);
}
#else
int8_t normalise(int32_t* v, uint8_t n) {
    uint32_t big = 0;
    for (uint8_t i = 0; i < n; ++i) big |= abs32(v[i]); // the largest's top bit
    if (big == 0) return 0;
    // big = m 2^e with m in [2^31, 2^32): its top bit is 31 + e, to be moved to bit 27.
    const int8_t sh = static_cast<int8_t>(-4 - Num(big).e);
    for (uint8_t i = 0; i < n; ++i) {
        v[i] = sh < 0 ? v[i] >> -sh : static_cast<int32_t>(static_cast<uint32_t>(v[i]) << sh);
    }
    return sh;
}
#endif

// P' and P'' (x 2^scale) at `off` (Q29) past the current point; with `move`, that point becomes
// the current one.
void track_at(Track& k, uint32_t off, bool move, int32_t d1[2], int32_t d2[2]) {
    save_run_to_r17();
    if (k.bezier) {
        uint32_t t = k.b.t + off;
        if (move) k.b.t = t;
        int32_t t30 = static_cast<int32_t>(t << 1);
        for (uint8_t i = 0; i < 2; ++i) {
            const int32_t a = mul_q30(k.b.h[2][i], t30);
            const int32_t q = k.b.h[1][i] + a;
            d2[i] = q + a;
            d1[i] = k.b.h[0][i] + mul_q30(q, t30);
        }
        return;
    }
    int32_t v[2];
    memcpy(v, k.e.dir[0], sizeof(v));
    if (off) {
        int32_t rot[2], h = static_cast<int32_t>(off << 1);
        if (k.clockwise) h = -h;
        rotation(h, rot);
        rotate(v, rot);
    }
    if (move) memcpy(k.e.dir[0], v, sizeof(v));
    // (-P'': only its size is used.)
    ellipse_at(k.e.r, v, k.clockwise, d1, d2);
}

// |(x, y)| for signed x, y, or with `with_rise` |(x, y, rise)|. (Inlined into probe(): its frame
// grows by q, but the call level, deeper, goes.)
void norm(const int32_t v[2], const Track& k, bool with_rise, Num& r) {
    Num q[3];
    components(v, k.rise, q);
    root_sum_squares(q, static_cast<uint8_t>(2 + with_rise), r);
}

// The unit tangent (P', w') / |(P', w')| at the current point, Q29. Where P' = 0 (a Bezier whose
// end arm is null), P' a little inside the curve (2^-12 of t): the direction of P''(0), or of
// -P''(1), to 2^-12 |P'''| / |P''| rad.
void tangent(Track& k, int32_t out[3]) {
    // P' and P'' where probe() keeps them.
    int32_t* d = scratch<int32_t[4], kCurveProbeAt>();
    asm("" : "+r"(d));
    track_at(k, 0, false, d, d + 2);
    if ((d[0] | d[1]) == 0) {
        const uint32_t in = kOneQ29 >> 12; // backwards from t = 1: modulo 2^32
        track_at(k, k.b.t ? static_cast<uint32_t>(0u - in) : in, false, d, d + 2);
    }
    Num q[3];
    const uint8_t neg = components(d, k.rise, q);
    unit_vector(q, 3, static_cast<uint8_t>(neg | k.w_down << 2), 29, out);
}

// The track at `off` (Q29) past its current point, which with `move` becomes the current one:
// the speed sqrt(|P'|^2 + w'^2) (x 2^scale) into `n1` (written where the caller keeps it, not
// returned: no copies through the frames) and, with `half`, |P'| / |P''| / 2 (Q29: the widest
// panel there). On a Bezier, the radius of curvature |P'|^3 / |P' x P''| (x 2^scale x 2^30) there
// is kept in k.rmin when it is the smallest so far.
void probe(Track& k, uint32_t off, bool move, uint32_t* half, Num& n1) {
    save_run_from_r8();
    // P' and P'' in the scratch RAM (scratch.h: dead there under push_line()), not in a frame
    // on the deepest stack of the firmware.
    static_assert(4 * sizeof(int32_t) <= kCurveProbeBytes, "P' and P'' fit their share");
    int32_t* d1 = scratch<int32_t[4], kCurveProbeAt>();
    asm("" : "+r"(d1)); // (reached through a pointer register: lds/sts are 4 bytes)
    int32_t* const d2 = d1 + 2;
    track_at(k, off, move, d1, d2);
    norm(d1, k, false, n1);
    if (k.bezier) {
        // |P' x P''| / 2^30: both are below 2^30, and where the radius is smallest this keeps 20
        // bits. The radius is kept x 2^30 (below 2^90: under the 2^100 of none), and shape()
        // takes the 2^30 off with the scale.
        int32_t cross = mul_q30(d1[0], d2[1]) - mul_q30(d1[1], d2[0]);
        if (cross != 0) {
            Num rc = n1;
            rc.mul(n1).mul(n1).div(abs32(cross));
            if (rc.cmp(k.rmin) < 0) k.rmin = rc;
        }
    }
    if (half) {
        Num n2;
        norm(d2, k, false, n2);
        *half = n2.m ? Num(n1).div(n2).shift(28).u32() : 0xFFFFFFFFul; // P'' = 0: a line
    }
    if (k.w_counts) norm(d1, k, true, n1);
}

// Adds to `total` the length of the track over `span` (Q29) from its current point, x 2^29 x 18
// x 2^scale: panels of 3 Gauss-Legendre nodes, each at most half the local scale |P'| / |P''|
// wide (so that the nearest singularity of |P'| in the complex plane is at least two widths
// away: 1e-7 relative), and at most kWidestArcQ29 or kWidestBezierQ29. On a Bezier, the radii of
// curvature are sampled at every node and panel end, and these crowd where the curve turns
// tightly.
void track_length(Track& track, uint32_t span, Num& total) {
    // The track's address as a pointer the callees cannot see through (it is a constant,
    // scratch.h): probe() and track_at() then reach it with displacements from a pointer
    // register (2 bytes an instruction), not at absolute addresses (lds/sts, 4 bytes).
    Track* kp = &track;
    asm("" : "+r"(kp));
    Track& k = *kp;
    uint32_t w = 0;
    for (;;) {
        Num sum, b, mid;
        probe(k, w, true, &k.half, sum); // the end of the last panel (at first, the start)
        span -= w;
        if (span == 0) break;
        w = k.half;
        const uint32_t widest = k.bezier ? kWidestBezierQ29 : kWidestArcQ29;
        if (w > widest) w = widest;
        if (w < kNarrowestQ29) w = kNarrowestQ29;
        if (w > span) w = span;
        // Nodes at g, w / 2 and w - g, weights 5, 8, 5 (/ 18).
        const uint32_t g = static_cast<uint32_t>(mul_q30(static_cast<int32_t>(w), kGaussQ30));
        probe(k, g, false, nullptr, sum);
        probe(k, w - g, false, nullptr, b);
        probe(k, w / 2, false, nullptr, mid);
        sum.add(b).mul(5).add(mid.mul(8));
        total.add(sum.mul(w));
    }
}

// curve_shape() with its track passed in: the track is then reached through a pointer, not
// through a stack frame too large for the AVR's displacement addressing. (Inlined into
// curve_shape(), its one caller: one call level fewer on the deepest stack.)
bool shape(const CurveParams& cp, int32_t dw_um, bool w_regulated, CurveShape& out, Track& k) {
    k.w_down = dw_um < 0;
    int8_t scale;
    uint32_t span = kOneQ29;
    uint8_t turns = 0;
    bool circle = false;
    Num len{};
    // w rises by |dw| per unit of the parameter: a Bezier's t, or (below) an arc's radian.
    k.rise.set(abs32(dw_um));
    if (cp.kind == kCurveArc) {
        const uint32_t* r = reinterpret_cast<const uint32_t*>(cp.b_um);
        k.clockwise = cp.clockwise != 0;
        // The sweep in (0, 2 pi], and with the extra full turns, radians.
        span = arc_directions(ends_of(cp), cp.a_um, r, k.clockwise, k.e.dir);
        if (span == 0) return false; // a null radius
        turns = cp.turns;
        // w rises linearly with the angle: dw / |sweep| per radian.
        Num ld[2]; // |sweep| (radians), and |dw| for a circle's length below
        ld[1] = k.rise;
        ld[0].set(kTurnQ29, -29).mul(turns).add(Num(span, -29));
        k.rise.div(ld[0]);
        memcpy(k.e.r, r, sizeof(k.e.r));
        scale = normalise(k.e.r, 2);
        const uint32_t hi = larger(r);
        const uint32_t lo = min32(r[0], r[1]);             // (the planner's copy)
        out.min_radius_um = Num(lo).mul(lo).div(hi).u32(); // b^2 / a at the flat ends
        if (lo == hi) {
            // A circle in closed form: r |sweep|, and a circular helix sqrt(plane^2 + dw^2).
            // (The quadrature gives the same to 1e-7, its speed being constant, but at ~20 times
            // the cycles: 0.7 M for a whole circle instead of 37 k, too slow for streams of short
            // arcs.)
            circle = true;
            ld[0].mul(lo);
            if (w_regulated) {
                root_sum_squares(ld, 2, len);
            } else {
                len = ld[0];
            }
            len.shift(8); // um x 256
        }
    } else {
        // Hodograph B'(t) = h0 + t (h1 + t h2): 3 D1, 6 D2, 3 D3 from the forward differences of
        // the points. The G-code checks (error:33) keep the control polygon below 2^23 µm, so
        // these fit. w rises by dw per unit of t.
        for (uint8_t i = 0; i < 2; ++i) {
            // The points start, a, b, end: 0, 2, 3, 1 of the row (start end a b, as the G-code
            // checks pin it), 2 bits each.
            int32_t q[4];
            const int32_t* row = cp.start_um + i; // (coordinate i of each point: no index add)
            for (uint8_t j = 0, seq = 0x78; j < 4; ++j, seq = static_cast<uint8_t>(seq >> 2)) {
                q[j] = row[2 * (seq & 3)];
            }
            differences(q);
            for (uint8_t j = 0; j < 3; ++j) {
                int32_t h = q[j + 1];
                h += h + h; // (products are library calls)
                if (j == 1) h += h;
                k.b.h[j][i] = h;
            }
        }
        scale = normalise(&k.b.h[0][0], 6);
        k.bezier = true;
        k.rmin.set(1, 100); // above any radius, and within range after the scale
    }
    k.rise.shift(scale);
    k.w_counts = w_regulated;
    tangent(k, out.start_dir);
    if (!circle) {
        track_length(k, span, len);
        // An ellipse's extra turns: a full turn from wherever.
        if (turns) {
            Num full{};
            track_length(k, kTurnQ29, full);
            len.add(full.mul(turns));
        }
        len.div(18).shift(static_cast<int8_t>(8 - 29 - scale)); // um x 256
    }
    if (k.bezier) {
        // (x 2^30, see probe(); none saturates)
        out.min_radius_um = k.rmin.shift(static_cast<int8_t>(-30 - scale)).u32();
    } else {
        memcpy(k.e.dir[0], k.e.dir[1], sizeof(k.e.dir[0]));
    }
    tangent(k, out.end_dir);
    if (len.m == 0) return false;
    out.len_q8 = len.u32();
    return true;
}

} // namespace

// (Defined here, in the lowest module that uses it, so that linking the curves alone needs it
// and nothing more.)
alignas(alignof(void*)) uint8_t g_scratch[kScratchBytes]; // 1 on the AVR, 8 on the host

// The track in the scratch RAM (scratch.h: dead there under push_line()), not in a 46-byte frame
// on the deepest stack of the firmware.
static_assert(sizeof(Track) <= kCurveTrackBytes && kCurveTrackAt % alignof(Track) == 0,
              "the track fits its share of the scratch RAM");
bool curve_shape(const CurveParams& cp, int32_t dw_um, bool w_regulated, CurveShape& out) {
    Track* kp = &scratch<Track, kCurveTrackAt>();
    Track& k = *kp;
    memset(&k, 0, sizeof(k)); // (out's tangents are written in full: unit_vector() gives 0 for a
                              // null vector)
    return shape(cp, dw_um, w_regulated && dw_um != 0, out, k);
}

} // namespace ll
