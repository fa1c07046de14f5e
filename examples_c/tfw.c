/* Tension-field wrinkles through the C API (capability "tfw"): solves the shipped stretched
   sheet (examples/tfw/stretched_sheet.json, about 3 s natively) once, checks the status and
   that the wrinkles are real (peak amplitude in [0.28, 0.50] mm, docs/benchmarks/tfw.md,
   "Answers"), copies out the base mesh, the field, the stats and the SQP history, writes the
   wrinkled mesh as OBJ; then a small sheet built from arrays, and misuse: NULLs, bad JSON,
   NaN in arrays, wrong struct sizes, cancel from the progress callback. Without "tfw" every
   call must answer UNSUPPORTED. Run from the repository root. */
#include <math.h>
#include "test_util.h"

#define SHEET "examples/tfw/stretched_sheet.json"
#define OUT_OBJ "target/tfw_sheet_c.obj"

/* A small stretched sheet as arrays: NX x NY grid on 0.25 x 0.1 m, stretched 5% along x,
   both short edges clamped (the shipped sheet at a lower resolution). */
#define NX 13
#define NY 6
typedef struct {
    double rest[2 * NX * NY], pos[3 * NX * NY];
    uint32_t tris[6 * (NX - 1) * (NY - 1)], clamped[2 * NY];
} Arrays;

static void make_arrays(Arrays *a) {
    int i, j, k = 0;
    for (j = 0; j < NY; j++)
        for (i = 0; i < NX; i++) {
            int v = j * NX + i;
            a->rest[2 * v] = 0.25 * i / (NX - 1);
            a->rest[2 * v + 1] = 0.1 * j / (NY - 1);
            a->pos[3 * v] = (a->rest[2 * v] - 0.125) * 1.05;
            a->pos[3 * v + 1] = a->rest[2 * v + 1] - 0.05;
            a->pos[3 * v + 2] = 0.0;
        }
    for (j = 0; j + 1 < NY; j++)
        for (i = 0; i + 1 < NX; i++) {
            uint32_t p = (uint32_t)(j * NX + i), q = p + 1, r = p + NX + 1, s = p + NX;
            uint32_t t[6];
            if ((i + j) % 2 == 0) {
                t[0] = p, t[1] = q, t[2] = r, t[3] = p, t[4] = r, t[5] = s;
            } else {
                t[0] = p, t[1] = q, t[2] = s, t[3] = q, t[4] = r, t[5] = s;
            }
            memcpy(a->tris + k, t, sizeof t);
            k += 6;
        }
    for (j = 0; j < NY; j++) {
        a->clamped[j] = (uint32_t)(j * NX);
        a->clamped[NY + j] = (uint32_t)(j * NX + NX - 1);
    }
}

static int cancel_at_first(void *user, const PleatProgress *info) {
    int *calls = (int *)user;
    (void)info;
    return ++*calls >= 1;
}

static int count_calls(void *user, const PleatProgress *info) {
    int *calls = (int *)user;
    CHECK(info->fraction >= 0.0 && info->fraction <= 1.0 && info->stage != NULL);
    ++*calls;
    return 0;
}

static void solve_sheet(void) {
    PleatTfwScene *scene = NULL;
    PleatTfwResult *res = NULL;
    PleatMesh *base = NULL, *wrinkled = NULL;
    PleatCwf *cwf = NULL;
    PleatTfwStats st;
    PleatWrinkleEvalParams ep = pleat_wrinkle_eval_params_default();
    double *hist, *amp, peak = 0, zmin = 1e9, zmax = -1e9, *pos;
    size_t n, i, nv;
    int calls = 0;

    CHECK_STATUS(pleat_tfw_scene_read_file(SHEET, &scene), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_tfw_solve(scene, NULL, count_calls, &calls, &res), PLEAT_STATUS_OK);
    if (!res) {
        pleat_tfw_scene_destroy(scene);
        return;
    }
    CHECK(calls > 0);
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    CHECK_STATUS(pleat_tfw_result_get_stats(res, &st), PLEAT_STATUS_OK);
    CHECK(st.struct_size == sizeof st);
    CHECK(st.status == PLEAT_TFW_STATUS_CONVERGED || st.status == PLEAT_TFW_STATUS_NOT_CONVERGED);
    CHECK(st.vertex_count > 500 && st.sqp_iterations > 0);
    CHECK(st.peak_amplitude >= 0.28e-3 && st.peak_amplitude <= 0.50e-3);
    CHECK(st.energy <= st.initial_energy && st.curl_residual <= 1e-10);
    /* appended 2026-11-29: nothing snapped (snapping is off by default), no SQP rescue */
    CHECK(st.snapped_loops == 0 && st.snap_max_correction == 0.0);
    CHECK(st.sqp_rescue_iteration == -1);
    printf("sheet: status %u, %llu vertices, %u SQP iterations, peak amplitude %.3f mm, "
           "base %.2f s, SQP %.2f s\n",
           st.status, (unsigned long long)st.vertex_count, st.sqp_iterations,
           st.peak_amplitude * 1e3, st.seconds_base, st.seconds_sqp);

    /* the history: energy non-increasing, wall time increasing */
    n = pleat_tfw_result_history_count(res);
    CHECK(n == st.sqp_iterations);
    hist = (double *)malloc((PLEAT_TFW_HISTORY_COLUMNS * n + 1) * sizeof *hist);
    CHECK_STATUS(pleat_tfw_result_copy_history(res, hist, n), PLEAT_STATUS_OK);
    for (i = 1; i < n; i++) {
        CHECK(hist[4 * i] <= hist[4 * (i - 1)]);
        CHECK(hist[4 * i + 3] >= hist[4 * (i - 1) + 3]);
    }
    if (n > 0) {
        CHECK(fabs(hist[4 * (n - 1)] - st.energy) <= 1e-9 * fabs(st.energy));
        CHECK_STATUS(pleat_tfw_result_copy_history(res, hist, n - 1),
                     PLEAT_STATUS_LIMIT_EXCEEDED);
    }
    free(hist);

    /* base mesh and field as the existing handles */
    CHECK_STATUS(pleat_tfw_result_base_mesh(res, &base), PLEAT_STATUS_OK);
    nv = pleat_mesh_vertex_count(base);
    CHECK(nv == st.vertex_count && pleat_mesh_triangle_count(base) == st.triangle_count);
    CHECK_STATUS(pleat_tfw_result_cwf(res, &cwf), PLEAT_STATUS_OK);
    CHECK(pleat_cwf_vertex_count(cwf) == nv);
    amp = (double *)malloc((nv + 1) * sizeof *amp);
    CHECK_STATUS(pleat_cwf_copy_amplitude(cwf, amp, nv), PLEAT_STATUS_OK);
    for (i = 0; i < nv; i++)
        peak = amp[i] > peak ? amp[i] : peak;
    CHECK(peak == st.peak_amplitude);
    free(amp);

    /* the wrinkled mesh (2 levels keep the valgrind run short), with the v2 term */
    ep.levels = 2;
    CHECK_STATUS(pleat_tfw_result_evaluate(res, &ep, 1, NULL, NULL, &wrinkled), PLEAT_STATUS_OK);
    CHECK(pleat_mesh_triangle_count(wrinkled) == 16 * st.triangle_count);
    pos = (double *)malloc(3 * pleat_mesh_vertex_count(wrinkled) * sizeof *pos + 1);
    pleat_mesh_copy_positions_f64(wrinkled, pos, pleat_mesh_vertex_count(wrinkled), 0);
    for (i = 0; i < pleat_mesh_vertex_count(wrinkled); i++) {
        zmin = pos[3 * i + 2] < zmin ? pos[3 * i + 2] : zmin;
        zmax = pos[3 * i + 2] > zmax ? pos[3 * i + 2] : zmax;
    }
    free(pos);
    CHECK(zmax - zmin > 0.3e-3); /* out-of-plane relief of a few tenths of a millimetre */
    CHECK_STATUS(pleat_mesh_write_file(wrinkled, OUT_OBJ), PLEAT_STATUS_OK);
    ep.flags = PLEAT_WRINKLE_FIELD_Z;
    CHECK_STATUS(pleat_tfw_result_evaluate(res, &ep, 1, NULL, NULL, &wrinkled),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    ep.flags = 0;
    CHECK_STATUS(pleat_tfw_result_evaluate(res, &ep, 2, NULL, NULL, &wrinkled),
                 PLEAT_STATUS_INVALID_ARGUMENT);

    /* the library's wave counter: the automatic section crosses the sheet's 5 periods */
    {
        PleatTfwWaveCount w, g;
        const double zero[3] = {0, 0, 0};
        memset(&w, 0, sizeof w);
        w.struct_size = sizeof w;
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, NULL, NULL, 0, &w), PLEAT_STATUS_OK);
        CHECK(w.struct_size == sizeof w && w.samples > 0);
        CHECK(w.waves >= 4.0 && w.waves <= 6.0);
        CHECK(w.peak_amplitude >= 0.28e-3 && w.peak_amplitude <= 0.50e-3);
        printf("waves %.1f (peak %.3f mm) on the plane through (%.3f, %.3f, %.3f) normal "
               "(%g, %g, %g)\n",
               w.waves, w.peak_amplitude * 1e3, w.point[0], w.point[1], w.point[2],
               w.normal[0], w.normal[1], w.normal[2]);
        g = w;
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, w.point, w.normal, w.closed, &g),
                     PLEAT_STATUS_OK);
        CHECK(g.waves == w.waves);
        /* min_radius (appended 2026-11-27): samples nearer the section point are dropped */
        g.min_radius = 0.02;
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, w.point, w.normal, w.closed, &g),
                     PLEAT_STATUS_OK);
        CHECK(g.min_radius == 0.02 && g.samples > 0 && g.samples < w.samples);
        g.min_radius = -1.0;
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, w.point, w.normal, w.closed, &g),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        g.min_radius = 0.0;
        /* misuse: a zero normal, a point without a normal, too many levels, NULL out */
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, w.point, zero, 0, &g),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, w.point, NULL, 0, &g),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 9, NULL, NULL, 0, &g),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_tfw_result_count_waves(res, 2, NULL, NULL, 0, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
    }

    /* misuse of the getters */
    st.struct_size = 4;
    CHECK_STATUS(pleat_tfw_result_get_stats(res, &st), PLEAT_STATUS_INVALID_ARGUMENT);
    st.struct_size = 8; /* an old, short struct: only the first 8 bytes are filled */
    st.base_status = 12345;
    CHECK_STATUS(pleat_tfw_result_get_stats(res, &st), PLEAT_STATUS_OK);
    CHECK(st.struct_size == 8 && st.base_status == 12345);
    CHECK_STATUS(pleat_tfw_result_get_stats(NULL, &st), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_result_get_stats(res, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_result_base_mesh(res, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_result_cwf(NULL, &cwf), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_result_copy_history(res, NULL, 1000), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(pleat_tfw_result_history_count(NULL) == 0);

    pleat_mesh_destroy(wrinkled);
    pleat_mesh_destroy(base);
    pleat_cwf_destroy(cwf);
    pleat_tfw_result_destroy(res);
    pleat_tfw_scene_destroy(scene);
}

static void arrays_scene(void) {
    static Arrays a;
    PleatTfwScene *s = NULL;
    PleatTfwResult *r = NULL;
    PleatTfwMaterial m = pleat_tfw_material_default();
    PleatTfwParams p = pleat_tfw_params_default();
    PleatTfwStats st;
    const size_t nv = NX * NY, nt = 2 * (NX - 1) * (NY - 1);
    double saved, t[3] = {0, 0, 0};
    int calls = 0;
    make_arrays(&a);

    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, a.pos, &m, a.clamped,
                                             2 * NY, t, &s),
                 PLEAT_STATUS_OK);
    /* cancel from the progress callback: no output */
    CHECK_STATUS(pleat_tfw_solve(s, &p, cancel_at_first, &calls, &r), PLEAT_STATUS_CANCELLED);
    CHECK(r == NULL && calls == 1);
    p.sqp_max_iterations = 30;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_OK);
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    CHECK_STATUS(pleat_tfw_result_get_stats(r, &st), PLEAT_STATUS_OK);
    CHECK(st.vertex_count == nv && st.triangle_count == nt && st.peak_amplitude > 0);
    printf("arrays sheet: status %u, %u SQP iterations, peak amplitude %.3f mm\n", st.status,
           st.sqp_iterations, st.peak_amplitude * 1e3);
    pleat_tfw_result_destroy(r);
    r = NULL;

    /* the other SQP step solver (qp, appended 2026-11-27): the same sheet, curl <= 1e-10 */
    saved = st.peak_amplitude;
    p.qp = p.qp == PLEAT_TFW_QP_CLARABEL ? PLEAT_TFW_QP_PROJECTED_NEWTON : PLEAT_TFW_QP_CLARABEL;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_OK);
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    CHECK_STATUS(pleat_tfw_result_get_stats(r, &st), PLEAT_STATUS_OK);
    CHECK(st.peak_amplitude > 0 && st.curl_residual <= 1e-10);
    CHECK(fabs(st.peak_amplitude - saved) <= 0.05 * saved);
    printf("arrays sheet, qp %u: %u SQP iterations, peak amplitude %.3f mm\n", p.qp,
           st.sqp_iterations, st.peak_amplitude * 1e3);
    pleat_tfw_result_destroy(r);
    r = NULL;

    /* an obstacle from C: a plane 5 mm below the sheet; then misuse (no radius, bad kind,
       NaN point, NULLs), each leaving the scene as it was */
    {
        PleatTfwObstacle o = pleat_tfw_obstacle_default();
        o.point[2] = -5e-3;
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(s, &o), PLEAT_STATUS_OK);
        o.kind = PLEAT_TFW_OBSTACLE_SPHERE;
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(s, &o), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK(strstr(pleat_last_error(), "radius") != NULL);
        o.kind = 9;
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(s, &o), PLEAT_STATUS_INVALID_ARGUMENT);
        o = pleat_tfw_obstacle_default();
        o.point[0] = NAN;
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(s, &o), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(s, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_tfw_scene_add_obstacle(NULL, &o), PLEAT_STATUS_INVALID_ARGUMENT);
    }

    /* bad parameters */
    p = pleat_tfw_params_default();
    p.struct_size = 4;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    p.sqp_armijo = NAN;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    p.sqp_max_iterations = 0;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    p.w_rule = 7;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    p.qp = 7;
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    p.snap_periods = 2; /* appended 2026-11-29: 0 or 1 */
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_tfw_params_default();
    CHECK(p.valley_search == 1);
    p.valley_search = 2; /* appended 2026-11-29: 0 or 1 */
    CHECK_STATUS(pleat_tfw_solve(s, &p, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(pleat_last_error(), "valley_search") != NULL);
    CHECK_STATUS(pleat_tfw_solve(NULL, NULL, NULL, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_solve(s, NULL, NULL, NULL, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(r == NULL);
    pleat_tfw_scene_destroy(s);
    s = NULL;

    /* bad arrays: NULLs, NaN, out-of-range indices, bad material, short struct */
    CHECK_STATUS(pleat_tfw_scene_from_arrays(NULL, nv, a.tris, nt, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, NULL, nt, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, NULL, 0, NULL,
                                             NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, NULL, 3, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, 2, a.tris, nt, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, 0, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    saved = a.rest[7];
    a.rest[7] = NAN;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    a.rest[7] = saved;
    saved = a.pos[4];
    a.pos[4] = INFINITY;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, a.pos, NULL, NULL, 0, NULL,
                                             &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    a.pos[4] = saved;
    t[1] = NAN;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, a.clamped, 2 * NY,
                                             t, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    a.tris[5] = (uint32_t)nv;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    a.tris[5] = 0;
    a.clamped[0] = 100000;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, NULL, a.clamped, 2 * NY,
                                             NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    a.clamped[0] = 0;
    m.thickness = -1e-4;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, &m, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = pleat_tfw_material_default();
    m.young = NAN;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, &m, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = pleat_tfw_material_default();
    m.struct_size = 8;
    CHECK_STATUS(pleat_tfw_scene_from_arrays(a.rest, nv, a.tris, nt, NULL, &m, NULL, 0, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(s == NULL);
}

static void json_misuse(void) {
    PleatTfwScene *s = NULL;
    CHECK_STATUS(pleat_tfw_scene_from_json("{ not json", &s), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_json("{\"material\": {\"yung\": 1}}", &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_json(NULL, &s), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_from_json("{}", NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_tfw_scene_read_file("no/such/scene.json", &s), PLEAT_STATUS_IO);
    CHECK_STATUS(pleat_tfw_scene_read_file(NULL, &s), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(s == NULL);
    pleat_tfw_scene_destroy(NULL);
    pleat_tfw_result_destroy(NULL);
}

static void without_tfw(void) {
    PleatTfwScene *s = NULL;
    PleatTfwResult *r = NULL;
    PleatTfwParams p = pleat_tfw_params_default();
    CHECK(p.struct_size == sizeof p && p.sqp_max_iterations == 1000);
    CHECK_STATUS(pleat_tfw_scene_read_file(SHEET, &s), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_tfw_scene_from_json("{}", &s), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_tfw_solve(NULL, NULL, NULL, NULL, &r), PLEAT_STATUS_UNSUPPORTED);
    CHECK(pleat_tfw_result_history_count(NULL) == 0);
}

int main(void) {
    if (!pleat_has_feature("tfw")) {
        without_tfw();
        return finish("tfw (built without tfw)");
    }
    json_misuse();
    arrays_scene();
    solve_sheet();
    return finish("tfw");
}
