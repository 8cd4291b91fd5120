// SPDX-License-Identifier: Apache-2.0
/* tests/test_emission_depth.c: the ray caster's approximate mean emission depth.
 *
 * A sample of opacity a takes its light at the mean depth of its emission within its step,
 * 1/tau - 1/(e^tau - 1) step lengths from the front, tau = -ln(1 - a) (kernels/raycast.cl,
 * emission_depth). The kernel evaluates it by a branch-free fit; the plain-C twin evaluates the
 * same expression (tests/reference/cpu_reference.c, cpu_emission_depth), and the kernel-vs-twin
 * tests tie the two together. Here the twin's copy is held to its stated bound, 4.7e-4 of a step,
 * against the exact mean in double precision over a dense set of opacities: a uniform grid, a
 * stride through every float in [0, 1], powers of two down to the smallest subnormal, and the
 * last floats below 1 where the exact mean falls fastest. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "cpu_reference.h"

#define BOUND 4.7e-4 /* step lengths; stated in kernels/raycast.cl */

/* The exact mean emission depth, from tau alone: near tau = 0 its Taylor series, as the
 * difference cancels there. */
static double exact_depth(double a)
{
    if (!(a < 1.0))
        return 0.0;
    const double tau = -log1p(-a);
    if (tau < 1e-3)
        return 0.5 - tau / 12.0 + tau * tau * tau / 720.0;
    return 1.0 / tau - 1.0 / expm1(tau);
}

typedef struct worst {
    double err;
    float a;
    long count;
} worst;

static void check(worst *w, float a)
{
    const double e = fabs((double)cpu_emission_depth(a) - exact_depth(a));
    if (!(e <= w->err)) { /* NaN counts as worst */
        w->err = isnan(e) ? INFINITY : e;
        w->a = a;
    }
    ++w->count;
}

static void test_depth_at_the_ends(void **state)
{
    (void)state;
    assert_true(cpu_emission_depth(0.0f) == 0.5f);
    assert_true(cpu_emission_depth(1.0f) == 0.0f);
    assert_true(cpu_emission_depth(1.5f) == 0.0f);
    assert_true(cpu_emission_depth(NAN) == 0.0f);
    assert_true(cpu_emission_depth(INFINITY) == 0.0f);
    /* The last float below 1: tau = 24 ln 2, the mean 0.0601, not yet 0. */
    assert_true(fabs(cpu_emission_depth(nextafterf(1.0f, 0.0f)) - 0.0601122) < BOUND);
}

static void test_depth_within_bound(void **state)
{
    (void)state;
    worst w = {0.0, 0.0f, 0};
    for (uint32_t k = 0; k <= (1u << 20); ++k) /* uniform, a = 0 and a = 1 included */
        check(&w, (float)k / (float)(1u << 20));
    const uint32_t one = 0x3f800000u; /* every 257th float in [0, 1] */
    for (uint32_t b = 0; b <= one; b += 257u) {
        float a;
        memcpy(&a, &b, sizeof a);
        check(&w, a);
    }
    for (float a = 0.5f; a > 0.0f; a *= 0.5f) /* tiny a, down to the smallest subnormal */
        check(&w, a);
    float a = 1.0f;
    for (int i = 0; i < 100000; ++i) { /* the last 100000 floats below 1 */
        a = nextafterf(a, 0.0f);
        check(&w, a);
    }
    for (int i = 1; i <= 24; ++i)
        check(&w, 1.0f - ldexpf(1.0f, -i));
    print_message("emission depth: %ld opacities, largest error %.3g of a step at a = %.9g\n",
                  w.count, w.err, (double)w.a);
    assert_true(w.err <= BOUND);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_depth_at_the_ends),
        cmocka_unit_test(test_depth_within_bound),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
