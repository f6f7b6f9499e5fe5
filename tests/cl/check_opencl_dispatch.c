/*
 * check_opencl_dispatch: the backend dispatcher and forced failures: a bogus
 * TERRASHADE_OPENCL_DEVICE, no OpenCL platform (OCL_ICD_VENDORS pointing at
 * an empty directory, in a fresh process), the fp32 kernels in a fresh process,
 * buffers too large for the device, and concurrent threads.
 *
 * Never skips: without OpenCL support or an OpenCL device the tests fail and
 * say why.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <check.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include "terrashade.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"
#include "test_grid.h"
#include "test_run.h"
#include "cl_test_common.h"

static char g_self[4096]; /* this program, for the fresh-process tests */


START_TEST(test_dispatch)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[5];
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, s);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    ck_assert_int_eq(r.fell_back, 0);
    ts_cl_info info;
    ts_error e;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_ptr_nonnull(strstr(r.device, info.device));
    /* the device auto would pick, described without building it */
    ts_cl_info peek;
    ck_assert_int_eq(ts_cl_peek(&peek, &e), TS_OK);
    ck_assert_str_eq(peek.device, info.device);
    ck_assert_str_eq(peek.type, info.type);
    ck_assert_int_eq(peek.index, info.index);

    r = dispatch_normals(TS_BACKEND_C, s);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 0);

    /* auto: OpenCL on a GPU or accelerator; on a CPU device picked by
     * default (PoCL), the C backend, and it says why */
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_AUTO);
    ck_assert_int_eq(r.fell_back, 0);
    if (!strcmp(info.type, "CPU")) {
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_ptr_nonnull(strstr(r.reason, "is a CPU"));
    } else {
        ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    }
    /* auto with a device named explicitly: OpenCL */
    setenv("TERRASHADE_OPENCL_DEVICE", "0", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    unsetenv("TERRASHADE_OPENCL_DEVICE");

    setenv("TERRASHADE_BACKEND", "opencl", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_OPENCL);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    r = dispatch_normals(TS_BACKEND_C, s); /* an explicit argument wins */
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    setenv("TERRASHADE_BACKEND", "C", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_C);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    setenv("TERRASHADE_BACKEND", "cuda", 1);
    ts_grid g;
    make_dem(&g, s);
    float *a = tdem_floats(g.width * g.height * 3);
    ck_assert_int_eq(ts_backend_normals(TS_BACKEND_AUTO, &g, 0, a, a + g.width * g.height,
                                        a + 2 * g.width * g.height, NULL, &e),
                     TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_BACKEND"));
    free(a);
    free_dem(&g, s);
    clear_env();

    ts_backend b;
    ck_assert_int_eq(ts_backend_parse(" OpenCL ", &b, &e), TS_OK);
    ck_assert_int_eq(b, TS_BACKEND_OPENCL);
    ck_assert_int_eq(ts_backend_parse("gpu", &b, &e), TS_ERR_ARG);
    ck_assert_str_eq(ts_backend_name(TS_BACKEND_AUTO), "auto");
    ck_assert_int_eq(ts_backend_choose(TS_BACKEND_OPENCL, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
}
END_TEST

static int last_progress(double done, void *user)
{
    *(double *)user = done;
    return 0;
}

static int cancel_progress(double done, void *user)
{
    (void)done;
    (void)user;
    return 1;
}

/* Every product through the dispatcher, forced onto OpenCL. */
START_TEST(test_dispatch_products)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[4];
    scene sc;
    scene_make(&sc, s, 8, 0.0);
    ts_error e;
    ts_backend_report r;
    float *a = tdem_floats(sc.n * 8), *b = tdem_floats(sc.n * 8), *c = tdem_floats(sc.n);
    ck_assert_int_eq(
        ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &sc.o, a, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch horizon_compute", sc.h, a, sc.n * 8, TOL_HORIZON);
    ck_assert_int_eq(ts_backend_horizon_sweep(TS_BACKEND_OPENCL, &sc.g, 90.0, &sc.o, a, &r, &e),
                     TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch horizon_sweep", sc.h + sc.n * 2, a, sc.n, TOL_HORIZON);
    ck_assert_int_eq(ts_shm_compute(&sc.g, 77, 9, 1, 0, c, b, &e), TS_OK);
    ck_assert_int_eq(
        ts_backend_shm_compute(TS_BACKEND_OPENCL, &sc.g, 77, 9, 1, 0, a, a + sc.n, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch shm visibility", c, a, sc.n, TOL);
    expect_close("dispatch shm height", b, a + sc.n, sc.n, TOL);
    const ts_direct_request dc = scene_direct(&sc, 150, 30, c), dl = scene_direct(&sc, 150, 30, a);
    ck_assert_int_eq(ts_shade_direct(&dc, &e), TS_OK);
    ck_assert_int_eq(ts_backend_shade_direct(TS_BACKEND_OPENCL, &dl, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch direct", c, a, sc.n, TOL);
    const ts_sky_request sc_ = scene_sky(&sc, TS_SVF_RADIATIVE, c, NULL, NULL);
    const ts_sky_request sl = scene_sky(&sc, TS_SVF_RADIATIVE, a, NULL, NULL);
    ck_assert_int_eq(ts_sky_terms(&sc_, &e), TS_OK);
    ck_assert_int_eq(ts_backend_sky_terms(TS_BACKEND_OPENCL, &sl, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch svf", c, a, sc.n, TOL);
    /* an argument error is the C backend's error */
    ck_assert_int_eq(
        ts_backend_shm_compute(TS_BACKEND_OPENCL, &sc.g, 77, 91, 1, 0, a, NULL, &r, &e),
        TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "got 91"));
    /* progress on OpenCL ends at 1; a cancel is final, not a reason to
     * fall back to C */
    double last = -1;
    ts_horizon_opts po = sc.o;
    po.progress = last_progress;
    po.progress_user = &last;
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &po, a, &r, &e),
                     TS_OK);
    ck_assert(last == 1.0 && r.used == TS_BACKEND_OPENCL);
    po.progress = cancel_progress;
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &po, a, &r, &e),
                     TS_ERR_CANCELLED);
    ck_assert(!r.fell_back);
    ck_assert_ptr_nonnull(strstr(e.message, "cancelled"));
    free(a), free(b), free(c);
    scene_free(&sc, s);
}
END_TEST

START_TEST(test_bogus_device)
{
    require_opencl();
    clear_env();
    ts_error e;
    ts_cl_info info;
    int count = 0;
    ck_assert_int_eq(ts_cl_devices(NULL, 0, &count, &e), TS_OK);
    static const char *bad[] = {"99", "0:42", "7:0", "gpu", "-1", "1x"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        setenv("TERRASHADE_OPENCL_DEVICE", bad[i], 1);
        ts_status st = ts_cl_available(&info, &e);
        ck_assert_int_ne(st, TS_OK);
        ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_OPENCL_DEVICE"));
        printf("  TERRASHADE_OPENCL_DEVICE=%s: %s\n", bad[i], e.message);
        ck_assert_int_ne(ts_cl_peek(&info, &e), TS_OK);
        ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_OPENCL_DEVICE"));
        ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[5]);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
        ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_DEVICE"));
        r = dispatch_normals(TS_BACKEND_AUTO, &SHAPES[5]);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
    }
    setenv("TERRASHADE_OPENCL_DEVICE", "0:0", 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_int_eq(info.platform_index, 0);
    ck_assert_int_eq(info.device_index, 0);
    char last[16];
    snprintf(last, sizeof last, "%d", count - 1);
    setenv("TERRASHADE_OPENCL_DEVICE", last, 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    clear_env();
}
END_TEST

/* Fresh processes: this program re-run with a mode argument. */
static int run_child(const char *mode, const char *env_name, const char *env_value)
{
    fflush(stdout);
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        if (env_name)
            setenv(env_name, env_value, 1);
        execl(g_self, g_self, mode, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* Child: no platform at all (OCL_ICD_VENDORS is an empty directory). */
static int child_no_platform(void)
{
    ts_error e;
    ts_cl_info info;
    ts_status st = ts_cl_available(&info, &e);
    printf("  child, OCL_ICD_VENDORS=%s: ts_cl_available: %s\n", getenv("OCL_ICD_VENDORS"),
           st == TS_OK ? "OK" : e.message);
    if (st == TS_OK || !strstr(e.message, "no OpenCL platform"))
        return 1;
    ts_grid g;
    if (ts_grid_create(&g, 13, 11, 30, 30, &e) != TS_OK)
        return 2;
    for (int i = 0; i < 13 * 11; i++)
        g.z[i] = (float)(i % 7) * 3.0f;
    float *a = malloc(3 * 143 * sizeof *a), *b = malloc(3 * 143 * sizeof *b);
    ts_backend_report r;
    int rc = 0;
    if (ts_normals(&g, a, a + 143, a + 286, &e) != TS_OK)
        rc = 3;
    for (int k = 0; k < 2 && !rc; k++) {
        ts_backend want = k ? TS_BACKEND_AUTO : TS_BACKEND_OPENCL;
        if (ts_backend_normals(want, &g, 0, b, b + 143, b + 286, &r, &e) != TS_OK)
            rc = 4;
        else if (r.used != TS_BACKEND_C || !r.fell_back || !strstr(r.reason, "no OpenCL platform"))
            rc = 5;
        else if (memcmp(a, b, 3 * 143 * sizeof *a))
            rc = 6;
        printf("  child: dispatch %s ran %s on %s, fell back: %s\n", ts_backend_name(want),
               r.backend, r.device, r.reason);
    }
    free(a);
    free(b);
    ts_grid_free(&g);
    return rc;
}

START_TEST(test_no_platform)
{
    require_opencl();
    char dir[] = "/tmp/ts_no_icd_XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    int rc = run_child("--child-no-platform", "OCL_ICD_VENDORS", dir);
    rmdir(dir);
    ck_assert_msg(rc == 0, "the no-platform child failed with %d", rc);
}
END_TEST

/* Child: kernels in float only (a device without cl_khr_fp64). */
static int child_fp32(void)
{
    ts_error e;
    ts_cl_info info;
    if (ts_cl_available(&info, &e) != TS_OK || info.fp64) {
        printf("  child fp32: %s\n", info.fp64 ? "fp64 still on" : e.message);
        return 1;
    }
    const dem_spec s = {67, 59, 30, 1, 1, 0, 12};
    ts_grid g;
    make_dem(&g, &s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 8;
    size_t n = (size_t)s.w * s.h;
    float *c = malloc(n * 8 * sizeof *c), *l = malloc(n * 8 * sizeof *l);
    int rc = 0;
    if (ts_horizon_compute(&g, &o, c, &e) != TS_OK || ts_cl_horizon_compute(&g, &o, l, &e))
        rc = 2;
    diff d = compare(c, l, n * 8);
    printf("  child fp32: horizon 67x59 holes geo, 8 dirs: max |C - OpenCL (float)| = %.3g deg\n",
           d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL_HORIZON))
        rc = 3;
    ts_shm_compute(&g, 33, 10, 0, 0, c, c + n, &e);
    if (!rc && ts_cl_shm_compute(&g, 33, 10, 0, 0, l, l + n, &e) != TS_OK)
        rc = 4;
    d = compare(c, l, 2 * n);
    printf("  child fp32: shm: max difference %.3g\n", d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL))
        rc = 5;
    if (!rc && (ts_normals(&g, c, c + n, c + 2 * n, &e) != TS_OK ||
                ts_cl_normals(&g, l, l + n, l + 2 * n, &e) != TS_OK))
        rc = 6;
    d = compare(c, l, 3 * n);
    printf("  child fp32: normals: max difference %.3g\n", d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL))
        rc = 7;
    free(c);
    free(l);
    ts_grid_free(&g);
    return rc;
}

START_TEST(test_fp32_kernels)
{
    require_opencl();
    int rc = run_child("--child-fp32", "TERRASHADE_OPENCL_FP64", "0");
    ck_assert_msg(rc == 0, "the float-kernel child failed with %d", rc);
}
END_TEST

/* Buffers larger than the device allows: a clean error, then fallback. */
START_TEST(test_too_large)
{
    require_opencl();
    clear_env();
    ts_error e;
    ts_cl_info info;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    /* A grid one row larger than the device's largest buffer, in pages
     * that are never touched (the upload is refused before any copy). */
    const int W = 1 << 20;
    const int H = (int)(info.max_alloc / sizeof(float) / (unsigned long long)W) + 1;
    size_t bytes = (size_t)W * H * sizeof(float);
    printf("  %d x %d grid (%zu MiB) against a %llu MiB maximum allocation\n", W, H, bytes >> 20,
           info.max_alloc >> 20);
    void *mem = mmap(NULL, 4 * bytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    ck_assert_msg(mem != MAP_FAILED, "mmap of %zu MiB: %s", 4 * bytes >> 20, strerror(errno));
    ts_grid g = {0};
    g.width = W;
    g.height = H;
    g.stride = W;
    g.cell_x = g.cell_y = 30;
    g.z = mem;
    float *o = (float *)mem + (size_t)W * H;
    ts_status st = ts_cl_normals(&g, o, o + (size_t)W * H, o + 2 * (size_t)W * H, &e);
    printf("  ts_cl_normals: %s\n", e.message);
    ck_assert_int_eq(st, TS_ERR_NOMEM);
    ck_assert_msg(strstr(e.message, "CL_INVALID_BUFFER_SIZE") ||
                      strstr(e.message, "CL_MEM_OBJECT_ALLOCATION_FAILURE") ||
                      strstr(e.message, "CL_OUT_OF_RESOURCES"),
                  "no OpenCL error name in '%s'", e.message);
    st = ts_cl_shm_compute(&g, 10, 10, 0, 0, o, NULL, &e);
    ck_assert_int_eq(st, TS_ERR_NOMEM);
    munmap(mem, 4 * bytes);

    /* The same through TERRASHADE_OPENCL_MAX_ALLOC on a small grid, where
     * the dispatcher can afford the fallback. */
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_int_eq(info.max_alloc, 4096);
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[4]); /* 7.8 kB */
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert_ptr_nonnull(strstr(r.reason, "CL_INVALID_BUFFER_SIZE"));
    ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_MAX_ALLOC"));
    /* horizons: the planes do not fit either */
    scene sc;
    scene_make(&sc, &SHAPES[4], 4, 0.0);
    float *h = tdem_floats(sc.n * 4);
    ck_assert_int_eq(ts_cl_horizon_compute(&sc.g, &sc.o, h, &e), TS_ERR_NOMEM);
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &sc.o, h, &r, &e),
                     TS_OK);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert(memcmp(h, sc.h, sc.n * 4 * sizeof *h) == 0);
    /* not a size: refused; a fraction of a unit is a size; 2^64 bytes and
     * more overflowed the count (undefined) */
    const char *bad[] = {"lots", "0x1000", "+0x10M", "17179869184G", "0.5", "-1k", "  "};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        setenv("TERRASHADE_OPENCL_MAX_ALLOC", bad[i], 1);
        ck_assert_int_ne(ts_cl_normals(&sc.g, h, h + sc.n, h + 2 * sc.n, &e), TS_OK);
        ck_assert_msg(strstr(e.message, "TERRASHADE_OPENCL_MAX_ALLOC"), "%s: %s", bad[i],
                      e.message);
    }
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "0.5M ", 1); /* once refused: below 1, a space */
    ck_assert_msg(ts_cl_normals(&sc.g, h, h + sc.n, h + 2 * sc.n, &e) == TS_OK, "0.5M: %s",
                  e.message);
    free(h);
    scene_free(&sc, &SHAPES[4]);
    clear_env();
}
END_TEST

/* Two threads on the shared device at once. */
typedef struct {
    const dem_spec *s;
    int which;
    double maxdiff;
    int fail;
} thread_job;

static void *thread_main(void *arg)
{
    thread_job *t = arg;
    ts_grid g;
    ts_error e;
    make_dem(&g, t->s);
    size_t n = (size_t)t->s->w * t->s->h;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 6;
    float *c = malloc(n * 6 * sizeof *c), *l = malloc(n * 6 * sizeof *l);
    for (int rep = 0; rep < 3; rep++) {
        ts_status a, b;
        size_t m = n;
        if (t->which == 0) {
            a = ts_horizon_compute(&g, &o, c, &e);
            b = ts_cl_horizon_compute(&g, &o, l, &e);
            m = n * 6;
        } else {
            a = ts_shm_compute(&g, 40.0 * rep, 15, 0, 0, c, NULL, &e);
            b = ts_cl_shm_compute(&g, 40.0 * rep, 15, 0, 0, l, NULL, &e);
        }
        diff d = compare(c, l, m);
        if (a != TS_OK || b != TS_OK || d.nan_mismatch)
            t->fail = 1;
        t->maxdiff = fmax(t->maxdiff, d.max);
    }
    free(c);
    free(l);
    ts_grid_free(&g);
    return NULL;
}

START_TEST(test_threads)
{
    require_opencl();
    thread_job jobs[2] = {{&SHAPES[5], 0, 0, 0}, {&SHAPES[4], 1, 0, 0}};
    pthread_t th[2];
    for (int i = 0; i < 2; i++)
        ck_assert_int_eq(pthread_create(&th[i], NULL, thread_main, &jobs[i]), 0);
    for (int i = 0; i < 2; i++)
        pthread_join(th[i], NULL);
    printf("  two threads: horizon max diff %.3g deg, shm %.3g\n", jobs[0].maxdiff,
           jobs[1].maxdiff);
    ck_assert(!jobs[0].fail && !jobs[1].fail);
    ck_assert(jobs[0].maxdiff <= TOL_HORIZON && jobs[1].maxdiff <= TOL);
}
END_TEST

static Suite *opencl_suite(void)
{
    Suite *s = suite_create("opencl_dispatch");
    TCase *d = tcase_create("dispatch and failures");
    tcase_set_timeout(d, 600);
    tcase_add_test(d, test_dispatch);
    tcase_add_test(d, test_dispatch_products);
    tcase_add_test(d, test_bogus_device);
    tcase_add_test(d, test_no_platform);
    tcase_add_test(d, test_fp32_kernels);
    tcase_add_test(d, test_too_large);
    tcase_add_test(d, test_threads);
    suite_add_tcase(s, d);
    return s;
}

int main(int argc, char **argv)
{
    ssize_t len = readlink("/proc/self/exe", g_self, sizeof g_self - 1);
    if (len <= 0)
        snprintf(g_self, sizeof g_self, "%s", argv[0]);
    else
        g_self[len] = '\0';
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1 && !strcmp(argv[1], "--child-no-platform"))
        return child_no_platform();
    if (argc > 1 && !strcmp(argv[1], "--child-fp32"))
        return child_fp32();
    return test_run_suite_mode(opencl_suite(), CK_VERBOSE);
}
