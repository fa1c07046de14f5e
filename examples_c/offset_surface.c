/* Offset surface of a dirty soup from C: guarantees checked with pleat_mesh_check, stats,
 * cancellation through the progress callback, and misuse of the new calls. */
#include <math.h>
#include "test_util.h"

static const double CUBE_P[] = {0, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1,
                                1, 0, 0, 1, 0, 1, 1, 1, 0, 1, 1, 1};
static const uint32_t CUBE_T[] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                  2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};

/* Two interpenetrating cubes, the second with flipped faces: a typical dirty soup. */
static PleatMesh *dirty_soup(void) {
    double p[48];
    uint32_t t[72];
    int i;
    PleatMesh *m = NULL;
    for (i = 0; i < 24; i++) {
        p[i] = CUBE_P[i];
        p[24 + i] = CUBE_P[i] + 0.4;
    }
    for (i = 0; i < 36; i++) t[i] = CUBE_T[i];
    for (i = 0; i < 12; i++) { /* flipped */
        t[36 + 3 * i] = CUBE_T[3 * i] + 8;
        t[36 + 3 * i + 1] = CUBE_T[3 * i + 2] + 8;
        t[36 + 3 * i + 2] = CUBE_T[3 * i + 1] + 8;
    }
    CHECK_STATUS(pleat_mesh_create_f64(p, 16, 0, t, 72, &m), PLEAT_STATUS_OK);
    return m;
}

static int g_calls = 0;
static int count_progress(void *user, const PleatProgress *info) {
    (void)user;
    g_calls++;
    return (info->fraction < 0.0 || info->fraction > 1.0) ? 1 : 0;
}
static int cancel_at_once(void *user, const PleatProgress *info) {
    (void)info;
    ++*(int *)user;
    return 1;
}

static void offset_guarantees(void) {
    PleatMesh *in = dirty_soup(), *out = NULL;
    PleatStats *stats = NULL;
    PleatOffsetParams params = pleat_offset_params_default();
    PleatMeshReport r;
    char json[4096];
    size_t needed = 0, i, n;
    params.screen_size = 40;
    CHECK_STATUS(pleat_offset_surface(in, &params, count_progress, NULL, &out, &stats),
                 PLEAT_STATUS_OK);
    CHECK(out != NULL && stats != NULL && g_calls > 0);
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check(out, 0, &r), PLEAT_STATUS_OK);
    printf("offset: %llu triangles, components=%llu watertight=%u manifold=%u "
           "self_intersection_free=%u genus=%lld, %.3f s, %d progress calls\n",
           (unsigned long long)r.triangle_count, (unsigned long long)r.component_count,
           r.is_watertight, r.is_manifold, r.self_intersection_free, (long long)r.total_genus,
           pleat_stats_total_seconds(stats), g_calls);
    CHECK(r.is_watertight && r.is_manifold && r.self_intersection_free);
    CHECK(r.component_count == 1 && r.total_genus == 0);
    n = pleat_stats_count(stats, PLEAT_STATS_KIND_VERIFIED);
    for (i = 0; i < n; i++) {
        const char *name = NULL;
        double v = 0;
        CHECK_STATUS(pleat_stats_entry(stats, PLEAT_STATS_KIND_VERIFIED, i, &name, &v),
                     PLEAT_STATUS_OK);
        printf("  verified %s = %g\n", name, v);
        CHECK(v == 1.0);
    }
    CHECK_STATUS(pleat_stats_to_json(stats, json, sizeof json, &needed), PLEAT_STATUS_OK);
    CHECK(needed > 0 && json[0] == '{');
    CHECK_STATUS(pleat_stats_entry(stats, PLEAT_STATS_KIND_STAGE, 100000, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_stats_destroy(stats);
    pleat_stats_destroy(NULL);
    pleat_mesh_destroy(out);
    pleat_mesh_destroy(in);
}

static void offset_cancel_and_misuse(void) {
    PleatMesh *in = dirty_soup(), *out = NULL;
    PleatOffsetParams params = pleat_offset_params_default();
    int calls = 0;
    CHECK_STATUS(pleat_offset_surface(in, NULL, cancel_at_once, &calls, &out, NULL),
                 PLEAT_STATUS_CANCELLED);
    CHECK(out == NULL && calls == 1);
    CHECK_STATUS(pleat_offset_surface(NULL, NULL, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_offset_surface(in, NULL, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    params.screen_size = NAN;
    CHECK_STATUS(pleat_offset_surface(in, &params, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    params.screen_size = -5;
    CHECK_STATUS(pleat_offset_surface(in, &params, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    params = pleat_offset_params_default();
    params.features = 7;
    CHECK_STATUS(pleat_offset_surface(in, &params, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    params = pleat_offset_params_default();
    params.screen_size = 1e6;
    params.memory_budget_bytes = 1 << 20;
    CHECK_STATUS(pleat_offset_surface(in, &params, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    params.struct_size = 0;
    CHECK_STATUS(pleat_offset_surface(in, &params, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(out == NULL);
    pleat_mesh_destroy(in);
}

int main(void) {
    if (!pleat_has_feature("lod")) {
        printf("offset_surface: SKIPPED (library built without feature lod)\n");
        return 0;
    }
    offset_guarantees();
    offset_cancel_and_misuse();
    return finish("offset_surface");
}
