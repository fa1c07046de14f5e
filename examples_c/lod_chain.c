/* Bake a chain of LODs (and a cage) from arrays or from a mesh file, verify every level with
 * pleat_mesh_check, and cancel a bake from the progress callback.
 *
 *   lod_chain            a generated torus
 *   lod_chain FILE       any mesh file pleat reads (obj, ply, off, stl, gltf)
 */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define RING 24
#define TUBE 12

/* A torus (radii 1 and 0.35) as caller arrays: RING x TUBE quads, two triangles each. */
static void make_torus(float *p, uint32_t *t) {
    int i, j, k = 0;
    const double two_pi = 6.283185307179586;
    for (i = 0; i < RING; i++) {
        for (j = 0; j < TUBE; j++) {
            double u = two_pi * i / RING, v = two_pi * j / TUBE;
            double r = 1.0 + 0.35 * cos(v);
            p[3 * (i * TUBE + j) + 0] = (float)(r * cos(u));
            p[3 * (i * TUBE + j) + 1] = (float)(r * sin(u));
            p[3 * (i * TUBE + j) + 2] = (float)(0.35 * sin(v));
        }
    }
    for (i = 0; i < RING; i++) {
        for (j = 0; j < TUBE; j++) {
            uint32_t a = (uint32_t)(i * TUBE + j);
            uint32_t b = (uint32_t)(((i + 1) % RING) * TUBE + j);
            uint32_t c = (uint32_t)(((i + 1) % RING) * TUBE + (j + 1) % TUBE);
            uint32_t d = (uint32_t)(i * TUBE + (j + 1) % TUBE);
            t[k++] = a; t[k++] = b; t[k++] = c;
            t[k++] = a; t[k++] = c; t[k++] = d;
        }
    }
}

static void verify(const char *what, const PleatMesh *m) {
    PleatMeshReport r;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_OK);
    printf("%s: %llu triangles, watertight=%u manifold=%u self_intersection_free=%u\n", what,
           (unsigned long long)r.triangle_count, r.is_watertight, r.is_manifold,
           r.self_intersection_free);
    CHECK(r.is_watertight == 1 && r.is_manifold == 1 && r.consistently_oriented == 1);
    CHECK(r.self_intersections_checked == 1 && r.self_intersection_free == 1);
}

static int print_progress(void *user_data, const PleatProgress *info) {
    int *calls = (int *)user_data;
    (*calls)++;
    CHECK(info != NULL && info->stage != NULL);
    CHECK(info->fraction >= 0.0 && info->fraction <= 1.0);
    return 0;
}

/* Screen sizes are halved when the C harness runs this program under valgrind's memcheck
   (PLEAT_HARNESS_MEMCHECK set): the same calls and code paths at a quarter of the offset work,
   which memcheck slows ~50x; CTest and the sanitizer runs keep the full sizes. */
static double size_scale(void) { return getenv("PLEAT_HARNESS_MEMCHECK") ? 0.5 : 1.0; }

static void bake_chain(const PleatMesh *input) {
    const double sizes[3] = {25.0 * size_scale(), 50.0 * size_scale(), 100.0 * size_scale()};
    PleatMesh *levels[3] = {NULL, NULL, NULL};
    PleatLodStats stats[3];
    PleatLodParams params = pleat_lod_params_default();
    int i, calls = 0;
    memset(stats, 0, sizeof stats);
    for (i = 0; i < 3; i++) stats[i].struct_size = sizeof stats[0];
    params.max_rounds = 8;
    params.flags = PLEAT_LOD_MEASURE_FLOOR;
    /* The input is clean, so the default (auto) would start the finest level from the input
       itself, which has no offset floor to measure: start from the offset surface. */
    params.start = PLEAT_LOD_START_OFFSET;
    CHECK_STATUS(pleat_lod_generate_chain(input, sizes, 3, &params, print_progress, &calls,
                                          levels, stats),
                 PLEAT_STATUS_OK);
    CHECK(calls > 0);
    for (i = 0; i < 3; i++) {
        char name[64];
        CHECK(levels[i] != NULL);
        if (!levels[i]) continue;
        snprintf(name, sizeof name, "LOD n_p=%g", sizes[i]);
        verify(name, levels[i]);
        printf("  stats: %llu faces, %u rounds, %.3f s, Hausdorff/l = %.4f (d/l = %.4f)\n",
               (unsigned long long)stats[i].face_count, stats[i].rounds,
               stats[i].seconds_total, stats[i].hausdorff_relative, 1.0 / sizes[i]);
        CHECK(stats[i].struct_size == sizeof stats[0]);
        CHECK(stats[i].face_count == pleat_mesh_triangle_count(levels[i]));
        CHECK(stats[i].watertight == 1 && stats[i].manifold == 1);
        CHECK(stats[i].self_intersection_free == 1);
        CHECK(stats[i].hausdorff_relative > 0.0 && stats[i].hausdorff_relative < 4.0 / sizes[i]);
        /* The two one-sided parts make up the two-sided figure. */
        CHECK(stats[i].hausdorff_relative ==
              (stats[i].hausdorff_in_to_out_relative > stats[i].hausdorff_out_to_in_relative
                   ? stats[i].hausdorff_in_to_out_relative
                   : stats[i].hausdorff_out_to_in_relative));
        /* The floor is measured on the level baked from the offset surface (the finest, n_p =
           100); coarser levels start from the finer result and report NaN. */
        CHECK(stats[i].started_from_input == 0);
        /* Ranks from the finest (n_p = 100, baked first); the finest never starts from a
           finer level. The stage times listed are part of the total. */
        CHECK(stats[i].chain_level == 2 - i);
        CHECK(stats[i].started_from_finer <= 1 && (i < 2 || stats[i].started_from_finer == 0));
        CHECK(stats[i].stalled <= 1 && stats[i].converged <= 1 && stats[i].fit_reverted <= 1);
        CHECK(stats[i].seconds_fit >= 0.0 && stats[i].seconds_measure > 0.0);
        CHECK(stats[i].seconds_offset + stats[i].seconds_simplify + stats[i].seconds_flow +
                  stats[i].seconds_align + stats[i].seconds_fit + stats[i].seconds_verify +
                  stats[i].seconds_measure <=
              stats[i].seconds_total * (1.0 + 1e-9));
        if (i == 2) {
            CHECK(stats[i].hausdorff_floor_relative >= 0.0 &&
                  stats[i].hausdorff_floor_relative < 2.0 / sizes[i]);
        } else {
            CHECK(stats[i].hausdorff_floor_relative != stats[i].hausdorff_floor_relative);
        }
    }
    CHECK(pleat_mesh_triangle_count(levels[0]) <= pleat_mesh_triangle_count(levels[2]));
    for (i = 0; i < 3; i++) pleat_mesh_destroy(levels[i]);
}

/* What a progress callback saw: the calling thread, the calls, the last fraction. */
typedef struct {
    pthread_t caller;
    int calls, stop_at, off_thread, backwards;
    double last;
} Watch;

static int watch_progress(void *user_data, const PleatProgress *info) {
    Watch *w = (Watch *)user_data;
    w->calls++;
    if (!pthread_equal(pthread_self(), w->caller)) w->off_thread++;
    if (info->fraction < w->last) w->backwards++;
    w->last = info->fraction;
    return w->stop_at > 0 && w->calls >= w->stop_at;
}

static Watch watch(int stop_at) {
    Watch w;
    memset(&w, 0, sizeof w);
    w.caller = pthread_self();
    w.stop_at = stop_at;
    return w;
}

/* A level's positions and indices, copied out. */
typedef struct {
    size_t nv, nt;
    double *pos;
    uint32_t *idx;
} Copy;

static Copy copy_of(const PleatMesh *m) {
    Copy c;
    c.nv = pleat_mesh_vertex_count(m);
    c.nt = pleat_mesh_triangle_count(m);
    c.pos = (double *)malloc(3 * c.nv * sizeof(double) + 1);
    c.idx = (uint32_t *)malloc(3 * c.nt * sizeof(uint32_t) + 1);
    CHECK_STATUS(pleat_mesh_copy_positions_f64(m, c.pos, c.nv, 0), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_copy_indices(m, c.idx, 3 * c.nt), PLEAT_STATUS_OK);
    return c;
}

/* On a pool of two threads a chain runs independent levels beside each other: the levels are
   those of a one-thread pool, the callback runs on this thread only with fractions that never
   go back, and a cancel is honoured at the report that asked for it (no call after it). Both
   starts: the clean torus's own (the input) and the offset surface. */
static void chain_on_pools(const PleatMesh *input) {
    const double sizes[3] = {25.0 * size_scale(), 50.0 * size_scale(), 100.0 * size_scale()};
    PleatLodParams params = pleat_lod_params_default();
    int start, run, i, k;
    params.max_rounds = 8;
    for (start = 0; start < 2; start++) {
        Copy c[2][3];
        int total = 0;
        params.start = start == 0 ? PLEAT_LOD_START_AUTO : PLEAT_LOD_START_OFFSET;
        for (run = 0; run < 2; run++) {
            PleatMesh *levels[3] = {NULL, NULL, NULL};
            Watch w = watch(0);
            CHECK_STATUS(pleat_set_thread_count(run == 0 ? 1 : 2), PLEAT_STATUS_OK);
            CHECK_STATUS(pleat_lod_generate_chain(input, sizes, 3, &params, watch_progress, &w,
                                                  levels, NULL),
                         PLEAT_STATUS_OK);
            CHECK(w.calls > 0 && w.off_thread == 0 && w.backwards == 0);
            total = w.calls;
            for (i = 0; i < 3; i++) {
                c[run][i] = copy_of(levels[i]);
                pleat_mesh_destroy(levels[i]);
            }
        }
        for (i = 0; i < 3; i++) {
            CHECK(c[0][i].nv == c[1][i].nv && c[0][i].nt == c[1][i].nt);
            if (c[0][i].nv == c[1][i].nv && c[0][i].nt == c[1][i].nt) {
                CHECK(memcmp(c[0][i].pos, c[1][i].pos, 3 * c[0][i].nv * sizeof(double)) == 0);
                CHECK(memcmp(c[0][i].idx, c[1][i].idx, 3 * c[0][i].nt * sizeof(uint32_t)) == 0);
            }
            for (run = 0; run < 2; run++) {
                free(c[run][i].pos);
                free(c[run][i].idx);
            }
        }
        /* the number of reports varies with the timing of the levels beside each other */
        for (k = 0; k < 2; k++) {
            int stop_at = k == 0 ? 3 : total / 2;
            PleatMesh *levels[3] = {NULL, NULL, NULL};
            Watch w = watch(stop_at);
            CHECK_STATUS(pleat_lod_generate_chain(input, sizes, 3, &params, watch_progress, &w,
                                                  levels, NULL),
                         PLEAT_STATUS_CANCELLED);
            CHECK(w.calls == stop_at && w.off_thread == 0);
            CHECK(levels[0] == NULL && levels[1] == NULL && levels[2] == NULL);
        }
        printf("chain on pools of 1 and 2 threads (start %s): same levels, %d reports\n",
               start == 0 ? "auto" : "offset", total);
    }
    CHECK_STATUS(pleat_set_thread_count(0), PLEAT_STATUS_OK);
}

static void bake_cage(const PleatMesh *input) {
    PleatMesh *cage = NULL;
    PleatLodStats st;
    PleatLodParams params = pleat_lod_params_default();
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    params.screen_size = 25.0 * size_scale();
    params.max_rounds = 5;
    CHECK_STATUS(pleat_cage_generate(input, &params, NULL, NULL, &cage, &st), PLEAT_STATUS_OK);
    if (!cage) return;
    verify("cage", cage);
    CHECK(st.encloses_input == 1);
    /* A single bake has no chain rank; a cage runs no fit. */
    CHECK(st.chain_level == -1 && st.started_from_finer == 0);
    CHECK(st.seconds_fit == 0.0 && st.fit_reverted == 0);
    /* The default clearance, a twentieth of d, measured exactly (not sampled). */
    CHECK(params.clearance == 0.05);
    CHECK(st.clearance_kept == 1);
    CHECK(st.clearance_required == 0.05 * st.offset_distance);
    CHECK(st.min_clearance >= st.clearance_required);
    CHECK(st.min_clearance_relative > 0.0);
    printf("cage n_p=%g: %llu triangles, min clearance %.3g d\n",
           params.screen_size, (unsigned long long)st.face_count,
           st.min_clearance / st.offset_distance);
    pleat_mesh_destroy(cage);
}

static int cancel_after_three(void *user_data, const PleatProgress *info) {
    int *calls = (int *)user_data;
    (void)info;
    return ++(*calls) >= 3;
}

static void cancel(const PleatMesh *input) {
    PleatMesh *out = NULL;
    int calls = 0;
    CHECK_STATUS(pleat_lod_generate(input, NULL, cancel_after_three, &calls, &out, NULL),
                 PLEAT_STATUS_CANCELLED);
    CHECK(calls == 3);
    CHECK(out == NULL);
    /* also with a custom thread pool: the callback still runs on this thread */
    calls = 0;
    CHECK_STATUS(pleat_set_thread_count(2), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_lod_generate(input, NULL, cancel_after_three, &calls, &out, NULL),
                 PLEAT_STATUS_CANCELLED);
    CHECK(calls == 3 && out == NULL);
    CHECK_STATUS(pleat_set_thread_count(0), PLEAT_STATUS_OK);
}

int main(int argc, char **argv) {
    PleatMesh *input = NULL;
    if (!pleat_has_feature("lod")) {
        printf("lod_chain: built without the lod feature, skipped\n");
        return 0;
    }
    if (argc > 1) {
        CHECK_STATUS(pleat_mesh_read_file(argv[1], &input), PLEAT_STATUS_OK);
    } else {
        static float p[3 * RING * TUBE];
        static uint32_t t[6 * RING * TUBE];
        make_torus(p, t);
        CHECK_STATUS(pleat_mesh_create_f32(p, RING * TUBE, 0, t, 6 * RING * TUBE, &input),
                     PLEAT_STATUS_OK);
    }
    if (!input) return finish("lod_chain");
    bake_chain(input);
    if (pleat_has_feature("cage")) bake_cage(input);
    cancel(input);
    /* eight chains on pools of one and two threads: natively and under the sanitizers, not
       under memcheck, which serializes threads */
    if (!getenv("PLEAT_HARNESS_MEMCHECK")) chain_on_pools(input);
    pleat_mesh_destroy(input);
    return finish("lod_chain");
}
