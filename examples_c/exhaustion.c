/* Resource exhaustion from C: a soup of 10^6 tiny components and a soup of 10^6
 * coincident vertices each get a clear answer (a report, a LOD or PLEAT_STATUS_LIMIT_EXCEEDED)
 * within the memory budget, and a LOD bake cancelled from the progress callback returns
 * PLEAT_STATUS_CANCELLED promptly, and so does pleat_mesh_check_with_progress (the latencies
 * are printed, not asserted).
 * Runs natively (10^6-element inputs take minutes under valgrind's memcheck); .ci/asan.sh runs
 * it under ASan + UBSan. */
#define _POSIX_C_SOURCE 199309L
#include <time.h>
#include "test_util.h"

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* n^3 disjoint right triangles with legs 1e-3 on an n x n x n lattice of the unit cube. */
static PleatMesh *tiny_components(uint32_t n) {
    size_t faces = (size_t)n * n * n, v = 0, t = 0;
    double *p = malloc(faces * 9 * sizeof *p);
    uint32_t *idx = malloc(faces * 3 * sizeof *idx);
    PleatMesh *m = NULL;
    uint32_t i, j, k;
    CHECK(p != NULL && idx != NULL);
    if (p == NULL || idx == NULL) {
        free(p);
        free(idx);
        return NULL;
    }
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            for (k = 0; k < n; k++) {
                double o[3];
                int c, corner;
                o[0] = (double)i / n;
                o[1] = (double)j / n;
                o[2] = (double)k / n;
                for (corner = 0; corner < 3; corner++) {
                    for (c = 0; c < 3; c++)
                        p[3 * (v + corner) + c] = o[c] + (corner == c + 1 ? 1e-3 : 0.0);
                    idx[t++] = (uint32_t)(v + corner);
                }
                v += 3;
            }
    CHECK_STATUS(pleat_mesh_create_f64(p, v, 0, idx, t, &m), PLEAT_STATUS_OK);
    free(p);
    free(idx);
    return m;
}

/* A unit tetrahedron whose 4 corners are each stored `copies` times and whose 4 faces are
 * repeated `copies` times, each copy on its own vertices. */
static PleatMesh *coincident_tetrahedron(uint32_t copies) {
    static const double C[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t F[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    size_t nv = (size_t)copies * 4;
    double *p = malloc(nv * 3 * sizeof *p);
    uint32_t *idx = malloc(nv * 3 * sizeof *idx);
    PleatMesh *m = NULL;
    uint32_t c;
    int i;
    CHECK(p != NULL && idx != NULL);
    if (p == NULL || idx == NULL) {
        free(p);
        free(idx);
        return NULL;
    }
    for (c = 0; c < copies; c++) {
        memcpy(p + 12 * (size_t)c, C, sizeof C);
        for (i = 0; i < 12; i++) idx[12 * (size_t)c + i] = 4 * c + F[i];
    }
    CHECK_STATUS(pleat_mesh_create_f64(p, nv, 0, idx, nv * 3, &m), PLEAT_STATUS_OK);
    free(p);
    free(idx);
    return m;
}

/* Full reports (self-intersections included: stacked copies of a face are counted per group of
 * duplicates, `pairs` expected), then a LOD at n_p 16 under a 1 GiB budget (a LOD or
 * LIMIT_EXCEEDED), then a 1 MiB budget (LIMIT_EXCEEDED before any work). */
static void answer(const char *name, PleatMesh *m, uint32_t flags, uint64_t components,
                   uint64_t welded_comps, uint64_t pairs) {
    PleatMeshReport r;
    PleatLodParams lp = pleat_lod_params_default();
    PleatMesh *lod = NULL;
    PleatStatus st;
    double t = now_s();
    if (m == NULL) return;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check(m, flags, &r), PLEAT_STATUS_OK);
    printf("%s: report %.2f s: V=%llu F=%llu components=%llu duplicate_faces=%llu "
           "intersecting_pairs=%llu\n",
           name, now_s() - t, (unsigned long long)r.vertex_count,
           (unsigned long long)r.triangle_count, (unsigned long long)r.component_count,
           (unsigned long long)r.duplicate_face_count,
           (unsigned long long)r.self_intersecting_pair_count);
    CHECK(r.component_count == components);
    CHECK(r.self_intersections_checked == 1 && r.self_intersecting_pair_count == pairs);
    CHECK(r.self_intersection_free == (pairs == 0));
    t = now_s();
    CHECK_STATUS(pleat_mesh_check(m, flags | PLEAT_CHECK_WELD, &r), PLEAT_STATUS_OK);
    printf("%s: welded report %.2f s: components=%llu\n", name, now_s() - t,
           (unsigned long long)r.component_count);
    CHECK(r.component_count == welded_comps);
    lp.screen_size = 16;
    lp.memory_budget_bytes = 1u << 30;
    t = now_s();
    st = pleat_lod_generate(m, &lp, NULL, NULL, &lod, NULL);
    printf("%s: LOD at n_p 16, 1 GiB: status %d in %.2f s (%s)\n", name, (int)st, now_s() - t,
           st == PLEAT_STATUS_OK ? "ok" : pleat_last_error());
    CHECK(st == PLEAT_STATUS_OK || st == PLEAT_STATUS_LIMIT_EXCEEDED);
    if (st == PLEAT_STATUS_OK) {
        CHECK_STATUS(pleat_mesh_check(lod, 0, &r), PLEAT_STATUS_OK);
        CHECK(r.is_watertight == 1 && r.self_intersection_free == 1);
    }
    pleat_mesh_destroy(lod);
    lod = NULL;
    lp.memory_budget_bytes = 1u << 20;
    CHECK_STATUS(pleat_lod_generate(m, &lp, NULL, NULL, &lod, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK(lod == NULL);
}

/* Cancels at the first progress call `after` seconds past `start`; records when. */
typedef struct {
    double start, after, requested;
    int calls;
} CancelAt;

static int cancel_after(void *user_data, const PleatProgress *info) {
    CancelAt *c = user_data;
    double t = now_s();
    (void)info;
    c->calls++;
    if (t - c->start < c->after) return 0;
    if (c->requested == 0) c->requested = c->start + c->after;
    return 1;
}

/* A LOD bake of `m` cancelled at several times; prints the worst request-to-return latency. */
static void cancellation_latency(PleatMesh *m) {
    static const double AFTER[] = {0.05, 0.3, 0.8, 1.5};
    PleatLodParams lp = pleat_lod_params_default();
    double worst = 0;
    size_t i;
    if (m == NULL) return;
    lp.screen_size = 16;
    /* This measures cancellation, not the budget: the up-front memory estimate counts
     * the fit's coverage samples, about 3.5 GiB for 10^6 tiny components at n_p 16 (measured
     * peak 1.96 GiB), which the default 2 GiB refuses up front. */
    lp.memory_budget_bytes = (uint64_t)8 << 30;
    for (i = 0; i < sizeof AFTER / sizeof AFTER[0]; i++) {
        CancelAt c = {0, 0, 0, 0};
        PleatMesh *lod = NULL;
        PleatStatus st;
        double end;
        c.after = AFTER[i];
        c.start = now_s();
        st = pleat_lod_generate(m, &lp, cancel_after, &c, &lod, NULL);
        end = now_s();
        if (st == PLEAT_STATUS_OK) {
            printf("  cancel after %.2f s: finished first (%.2f s)\n", AFTER[i], end - c.start);
            pleat_mesh_destroy(lod);
            continue;
        }
        CHECK_STATUS(st, PLEAT_STATUS_CANCELLED);
        CHECK(lod == NULL);
        printf("  cancel after %.2f s: returned %.3f s after the request (%d calls)\n", AFTER[i],
               end - (c.start + c.after), c.calls);
        if (end - (c.start + c.after) > worst) worst = end - (c.start + c.after);
    }
    printf("LOD cancellation from C: worst request-to-return %.3f s\n", worst);
}

/* Records the longest interval between progress calls (from `start`; never cancels). */
typedef struct {
    double start, last, longest;
    int calls;
} Gaps;

static int record_gap(void *user_data, const PleatProgress *info) {
    Gaps *g = user_data;
    double t = now_s();
    (void)info;
    g->calls++;
    if (t - g->last > g->longest) g->longest = t - g->last;
    g->last = t;
    return 0;
}

/* pleat_mesh_check_with_progress on `m` (self-intersections included): the longest interval
 * between calls of an uncancelled run (to the return included), then cancels at several
 * times; prints the worst request-to-return latency. The output is not written when
 * cancelled. */
static void check_cancellation_latency(const char *name, PleatMesh *m) {
    static const double AFTER[] = {0.05, 0.5, 1.0, 2.0};
    PleatMeshReport r;
    Gaps g = {0, 0, 0, 0};
    double worst = 0, end;
    size_t i;
    if (m == NULL) return;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    g.start = g.last = now_s();
    CHECK_STATUS(pleat_mesh_check_with_progress(m, 0, record_gap, &g, &r), PLEAT_STATUS_OK);
    end = now_s();
    if (end - g.last > g.longest) g.longest = end - g.last;
    printf("%s: check with progress %.2f s, %d calls, longest gap %.3f s\n", name,
           end - g.start, g.calls, g.longest);
    CHECK(g.calls >= 7);
    for (i = 0; i < sizeof AFTER / sizeof AFTER[0]; i++) {
        CancelAt c = {0, 0, 0, 0};
        PleatStatus st;
        c.after = AFTER[i];
        memset(&r, 0xAB, sizeof r);
        r.struct_size = sizeof r;
        c.start = now_s();
        st = pleat_mesh_check_with_progress(m, 0, cancel_after, &c, &r);
        end = now_s();
        if (st == PLEAT_STATUS_OK) {
            printf("  cancel after %.2f s: finished first (%.2f s)\n", AFTER[i], end - c.start);
            continue;
        }
        CHECK_STATUS(st, PLEAT_STATUS_CANCELLED);
        CHECK(r.vertex_count == 0xABABABABABABABABull);
        printf("  cancel after %.2f s: returned %.3f s after the request (%d calls)\n", AFTER[i],
               end - (c.start + c.after), c.calls);
        if (end - (c.start + c.after) > worst) worst = end - (c.start + c.after);
    }
    printf("%s: check cancellation from C: worst request-to-return %.3f s\n", name, worst);
}

int main(void) {
    PleatMesh *comps;
    setvbuf(stdout, NULL, _IONBF, 0);
    comps = tiny_components(100);
    PleatMesh *coinc = coincident_tetrahedron(250000);
    answer("10^6 tiny components", comps, 0, 1000000, 1000000, 0);
    /* 4 faces x C(250000, 2) stacked pairs */
    answer("10^6 coincident vertices", coinc, 0, 250000, 1, 4ull * (250000ull * 249999ull / 2));
    check_cancellation_latency("10^6 tiny components", comps);
    check_cancellation_latency("10^6 coincident vertices", coinc);
    cancellation_latency(comps);
    pleat_mesh_destroy(comps);
    pleat_mesh_destroy(coinc);
    return finish("exhaustion");
}
