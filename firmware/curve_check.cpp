// The curve module on the chip, for the simavr check sim/tests/fw_test_curve.cpp: the workload
// of tests/curve_workload.h (its hash is compared with the host's), then the figures of
// docs/curves.md, each between two writes to GPIOR0 (0x3E) that the check times:
//   1/2  an arc in the plane walked (next() per sample), 3/4 a helix, 5/6 a Bezier;
//   7/8  curve_shape() of a circle, 9/10 of a 50 x 5 mm ellipse, 11/12 of a Bezier;
//   20/21 around every next() of the Bezier (its longest call: a piece start); 99: done.
// Never part of the release image.
#include <avr/io.h>

#include "curve_workload.h"

// Read by the check, by name.
volatile uint32_t g_curve_hash;      ///< the workload's hash
volatile uint32_t g_curve_samples;   ///< the workload's walker samples
volatile uint32_t g_curve_walked[3]; ///< samples of the arc, the helix and the Bezier

namespace {

void mark(uint8_t v) {
    GPIOR0 = v;
}

uint32_t walk(ll::CurveWalker& w, bool each) {
    uint8_t moved, neg;
    uint32_t n = 0;
    for (;;) {
        if (each) mark(20);
        bool more = w.next(moved, neg);
        if (each) mark(21);
        if (!more) return n;
        ++n;
    }
}

} // namespace

int main() {
    ll::test::CurveWorkload load(1);
    load.run(40);
    g_curve_hash = load.hash;
    g_curve_samples = load.samples;

    // A circle of 1000 ticks, then an ellipse of 3000 x 1000 ticks rising 500 ticks, clockwise.
    ll::CurveWalker w{};
    ll::CurveWalker::Ends e = {{1000, 0, 0}, {1000, 0, 0}, {256000, 0}, {256000, 0}};
    const int32_t centre[2] = {0, 0};
    const uint32_t circle[2] = {256000, 256000}, ellipse[2] = {768000, 256000};
    w.arc(e, centre, circle, false, 0);
    mark(1);
    g_curve_walked[0] = walk(w, false);
    mark(2);
    e = {{3000, 0, 0}, {3000, 0, 500}, {768000, 0}, {768000, 0}};
    w.arc(e, centre, ellipse, true, 0);
    mark(3);
    g_curve_walked[1] = walk(w, false);
    mark(4);
    // A Bezier over 8000 x 2000 ticks.
    e = {{0, 0, 0}, {8000, 2000, 0}, {0, 0}, {2048000, 512000}};
    const int32_t p1[2] = {512000, 1024000}, p2[2] = {1536000, -512000};
    w.bezier(e, p1, p2);
    mark(5);
    g_curve_walked[2] = walk(w, true);
    mark(6);

    ll::CurveParams c{};
    ll::CurveShape sh;
    c.kind = ll::kCurveArc;
    c.start_um[0] = c.end_um[0] = c.b_um[0] = c.b_um[1] = 50000; // a whole circle of 50 mm
    mark(7);
    ll::curve_shape(c, 0, true, sh);
    mark(8);
    c.b_um[1] = 5000; // a whole ellipse of 50 x 5 mm
    mark(9);
    ll::curve_shape(c, 0, true, sh);
    mark(10);
    c = ll::CurveParams{};
    c.kind = ll::kCurveBezier;
    c.a_um[0] = 10000;
    c.a_um[1] = 20000;
    c.b_um[0] = 30000;
    c.b_um[1] = -10000;
    c.end_um[0] = 40000;
    c.end_um[1] = 10000;
    mark(11);
    ll::curve_shape(c, 0, true, sh);
    mark(12);
    mark(99);
    for (;;) {
    }
}
