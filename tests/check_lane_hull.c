/* The lockstep hull step's four forms (lane_hull.h): the scalar reference
 * (ts_lane_hull_step_scalar), the AVX2 step (ts_lane_hull_step_avx2),
 * ts_lane_hull_step as this CPU runs it (AVX-512 here and in CI), and the
 * same with the hulls' most read points kept beside them (AVX-512 only), each on
 * its own copy of the same synthetic block of lines, step by step: every
 * answer (occluder steps and distances) and every hull (sizes, far
 * pointers, points) must be the same bits. The blocks are built to reach
 * what a real sweep reaches only now and then: terraced heights with exact
 * ties, spikes, nodata holes, curvature, lines entering and leaving the
 * step's range at every offset of a vector, queries asked or not (hi_from,
 * hi_to, NaN heights), constant steps (the occluder's step from its
 * distance, k_step > 0) and per-row steps (the points' steps stored), and
 * the far-only sweep's delayed pushes (the scalar form's line by line,
 * the others' as this CPU runs them). The products' checksums at every
 * level (tests/driver/test_cpu_paths.py) test the same end to end. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lane_hull.h"
#include "terrashade.h"
#include "test_dem.h"
#include "test_run.h"

#define LINES 37   /* not a multiple of a vector's lines: partial vectors */
#define STEPS 700
#define PAD 16     /* the vector steps' loads beyond the last line */
#define SLOTS 64   /* the delayed pushes' ring */

enum { SCALAR, AVX2, NATIVE, TOPS, FORMS };
static const char *const form_names[FORMS] = {"scalar", "avx2", "ts_lane_hull_step",
                                              "ts_lane_hull_step with points beside"};

typedef struct {
    ts_hull_pt *pts;
    int n[LINES + PAD], far[LINES + PAD];
    int hi_k[LINES + PAD], lo_k[LINES + PAD];
    float hi_dd[LINES + PAD], lo_dd[LINES + PAD];
    ts_lane_pushes push;
    double beside[TS_BESIDE * (LINES + PAD)]; /* the TOPS form's */
} form_state;

typedef struct {
    double c, near_skip, k_step; /* k_step 0: per-row steps */
    double behind;               /* > 0: delayed pushes that far back */
    uint32_t seed;
} block_case;

/* The vector forms where ts_cpu_vector_level allows them (AVX2 at least:
 * ts_lane_hull_step then runs AVX2's or AVX-512's; the hulls' tops beside
 * them only with AVX-512, as the sweep keeps them). */
static int form_available(int f)
{
    return f == SCALAR || (f == TOPS ? ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512
                                     : ts_cpu_vector_level() >= TS_CPU_VECTORS_AVX2);
}

static void form_step(int f, form_state *st, const ts_lane_step *s)
{
    const ts_lane_hulls h = {st->pts, STEPS + 1, st->n, st->far, f == TOPS ? st->beside : NULL,
                             LINES + PAD};
    const ts_lane_occluders occ = {st->lo_k, st->hi_k, st->lo_dd, st->hi_dd};
    if (f == SCALAR) {
        ts_lane_hull_step_scalar(&h, s, &occ);
        return;
    }
    const int done = f == AVX2 ? ts_lane_hull_step_avx2(&h, s, &occ)
                               : ts_lane_hull_step(&h, s, &occ);
    ck_assert_msg(done, "%s did not take the step", form_names[f]);
}

/* Form f's answers and hulls against the scalar one's after step k (lines
 * j0..j1 answered; the points' steps too where `steps`: the vector steps
 * leave them unwritten under constant steps); 1 where they are the same
 * bits. */
static int same_as_scalar(const form_state *ref, const form_state *st, int f, int k, int j0,
                          int j1, int steps)
{
    for (int j = j0; j <= j1; j++) {
        const int jn = j + 1; /* the cell above's answer */
        if (st->hi_k[j] != ref->hi_k[j] || memcmp(&st->hi_dd[j], &ref->hi_dd[j], 4) ||
            st->lo_k[jn] != ref->lo_k[jn] || memcmp(&st->lo_dd[jn], &ref->lo_dd[jn], 4)) {
            printf("step %d line %d: %s answers hi %d %.9g lo %d %.9g, scalar hi %d %.9g lo %d "
                   "%.9g\n",
                   k, j, form_names[f], st->hi_k[j], st->hi_dd[j], st->lo_k[j + 1],
                   st->lo_dd[j + 1], ref->hi_k[j], ref->hi_dd[j], ref->lo_k[j + 1],
                   ref->lo_dd[j + 1]);
            return 0;
        }
    }
    for (int j = 0; j < LINES; j++) {
        if (st->n[j] != ref->n[j] || st->far[j] != ref->far[j]) {
            printf("step %d line %d: %s hull n %d far %d, scalar n %d far %d\n", k, j,
                   form_names[f], st->n[j], st->far[j], ref->n[j], ref->far[j]);
            return 0;
        }
        const ts_hull_pt *a = st->pts + (size_t)j * (STEPS + 1);
        const ts_hull_pt *b = ref->pts + (size_t)j * (STEPS + 1);
        for (int i = 0; i < ref->n[j]; i++)
            if (memcmp(&a[i].d, &b[i].d, 8) || memcmp(&a[i].g, &b[i].g, 8) ||
                (steps && a[i].k != b[i].k)) {
                printf("step %d line %d point %d: %s (%.17g, %.17g), scalar (%.17g, %.17g)\n", k,
                       j, i, form_names[f], a[i].d, a[i].g, b[i].d, b[i].g);
                return 0;
            }
    }
    return 1;
}

/* One block of STEPS steps through every available form; returns the
 * number of answers compared (queries that found an occluder counted in
 * *found). */
static long run_block(const block_case *bc, long *found)
{
    static float hs[LINES + PAD], hc[LINES + PAD], hn[LINES + PAD];
    static double d[LINES + PAD], ring_d[SLOTS * (LINES + PAD)], ring_g[SLOTS * (LINES + PAD)];
    form_state st[FORMS];
    int avail[FORMS];
    for (int f = 0; f < FORMS; f++) {
        avail[f] = form_available(f);
        st[f].pts = calloc((size_t)LINES * (STEPS + 1), sizeof(ts_hull_pt));
        ck_assert(st[f].pts && ts_lane_pushes_alloc(&st[f].push, LINES));
        ts_lane_pushes_reset(&st[f].push, LINES);
        for (int j = 0; j < LINES + PAD; j++) {
            st[f].n[j] = 0;
            st[f].far[j] = -1;
        }
    }
    for (size_t i = 0; i < sizeof ring_d / sizeof *ring_d; i++)
        ring_d[i] = NAN;
    uint32_t seed = bc->seed;
    long compared = 0;
    *found = 0;
    for (int j = 0; j < LINES + PAD; j++)
        d[j] = 0.0;
    for (int k = 0; k < STEPS; k++) {
        /* the lines on the grid: a range that moves by one line at a time
         * at both ends, through every offset of a vector */
        const int j0 = (k / 23) % 9, j1 = LINES - 1 - (k / 31) % 7;
        for (int j = j0; j <= j1; j++) {
            const double x = k + 5.0 * j;
            float h = (float)(2.5 * floor((x * 0.41 + 35.0 * sin(x * 0.017 + j)) / 2.5));
            if (tdem_xorshift32(&seed) % 53 == 0)
                h += (float)(tdem_xorshift32(&seed) % 400);
            if ((k / 29 + j) % 13 == 0)
                h = NAN;
            hs[j] = h;
            const uint32_t r1 = tdem_xorshift32(&seed), r2 = tdem_xorshift32(&seed);
            const uint32_t r3 = tdem_xorshift32(&seed), r4 = tdem_xorshift32(&seed);
            hc[j] = r1 % 19 == 0 ? NAN : h - (float)(r2 % 5) * 2.5f;
            hn[j] = r3 % 23 == 0 ? NAN : h + (float)(r4 % 3) * 2.5f;
            if (isnan(h) && tdem_xorshift32(&seed) % 2)
                hc[j] = hn[j] = 31.0f; /* a query where the line has no sample */
            if (bc->k_step > 0)
                d[j] = (double)k * bc->k_step;
            else if (k > 0)
                d[j] += 10.0 * (1.0 + 0.05 * sin(k * 0.7 + j));
        }
        ts_lane_step s = {k, j0, j1, j0 + (k % 3 == 0), j1 - (k % 5 == 0), d, hs, hc, hn, bc->c,
                          bc->near_skip, NULL, NULL, NULL, bc->k_step};
        if (bc->behind > 0) { /* as ts_far_store: the step's samples wait in the ring */
            double *rd = ring_d + (size_t)(k % SLOTS) * (LINES + PAD);
            double *rg = ring_g + (size_t)(k % SLOTS) * (LINES + PAD);
            for (int j = 0; j < LINES + PAD; j++)
                rd[j] = NAN;
            for (int j = j0; j <= j1; j++)
                if (!isnan(hs[j])) {
                    rd[j] = d[j];
                    rg[j] = hs[j] - bc->c * d[j] * d[j];
                }
        }
        for (int f = 0; f < FORMS; f++) {
            if (!avail[f])
                continue;
            if (bc->behind > 0) {
                ts_lane_step sf = s;
                for (int more = 1; more;) {
                    /* the scalar form with the scalar pushes, the others
                     * with this CPU's (AVX-512 here and in CI) */
                    more = (f == SCALAR ? ts_lane_delayed_pushes_scalar
                                        : ts_lane_delayed_pushes)(&st[f].push, ring_d, ring_g,
                                                                  LINES + PAD, SLOTS, bc->behind,
                                                                  &sf);
                    form_step(f, &st[f], &sf);
                }
            } else {
                form_step(f, &st[f], &s);
            }
        }
        for (int f = AVX2; f < FORMS; f++)
            ck_assert_msg(!avail[f] || same_as_scalar(&st[SCALAR], &st[f], f, k, j0, j1,
                                                       !(bc->k_step > 0)),
                          "%s differs from the scalar step at step %d", form_names[f], k);
        for (int j = j0; j <= j1; j++) {
            compared += 2;
            *found += (st[SCALAR].hi_k[j] >= 0) + (st[SCALAR].lo_k[j + 1] >= 0);
        }
    }
    for (int f = 0; f < FORMS; f++) {
        free(st[f].pts);
        ts_lane_pushes_free(&st[f].push);
    }
    return compared;
}

START_TEST(test_forms_same_bits)
{
    const double curved = (1 - TS_DEFAULT_REFRACTION) / (2 * TS_EARTH_RADIUS);
    static const block_case cases[] = {
        {0.0, 0.0, 10.0, 0.0, 1},      /* constant steps, no near field */
        {curved, 25.0, 10.0, 0.0, 2},  /* curvature, a near field */
        {0.0, 95.0, 0.0, 0.0, 3},      /* per-row steps */
        {curved, 120.0, 0.0, 0.0, 4},
        {0.0, 0.0, 10.0, 40.0, 5},     /* delayed pushes (the far-only sweep) */
        {curved, 0.0, 0.0, 150.0, 6},
    };
    for (int f = 0; f < FORMS; f++)
        printf("%s: %s\n", form_names[f],
               form_available(f) ? "compared" : "not at this CPU's level");
    printf("ts_lane_hull_step runs %s here\n", ts_cpu_vectors_name(ts_cpu_vector_level()));
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        long found;
        const long n = run_block(&cases[i], &found);
        printf("c %g, near %g m, k_step %g, behind %g m: %ld answers the same bits, %ld with "
               "an occluder\n",
               cases[i].c, cases[i].near_skip, cases[i].k_step, cases[i].behind, n, found);
        /* the blocks find occluders, and not everywhere (none is an answer too) */
        ck_assert(n > 30000 && found > n / 4 && found < n);
    }
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines reach the log before a failure exits */
    Suite *s = suite_create("lane_hull");
    TCase *tc = tcase_create("forms");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_forms_same_bits);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
