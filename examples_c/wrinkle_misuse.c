/* Every documented misuse of the wrinkle-field C API returns its status with a message and
   writes no output; nothing aborts. Without the "wrinkle" capability the wrinkle functions
   return UNSUPPORTED (checked here too); the edge-list functions exist in every build. */
#include "wrinkle_util.h"

#define N 4 /* 4x4 grid: 16 vertices, 18 triangles, 33 edges */

static void misuse_edges(void) {
    PleatMesh *g = make_grid(N);
    uint32_t e[2 * 33];
    CHECK(pleat_mesh_edge_count(g) == 33 && pleat_mesh_edge_count(NULL) == 0);
    CHECK_STATUS(pleat_mesh_copy_edges(g, e, 33), PLEAT_STATUS_OK);
    CHECK(e[0] == 0 && e[1] == 1 && e[2] == 0 && e[3] == 4 && e[4] == 0 && e[5] == 5);
    CHECK(e[2 * 32] == 14 && e[2 * 32 + 1] == 15);
    CHECK_STATUS(pleat_mesh_copy_edges(g, e, 32), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_mesh_copy_edges(g, NULL, 33), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_copy_edges(NULL, e, 33), PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_mesh_destroy(g);
}

/* A valid plane-wave field on the grid for the tests below. */
typedef struct {
    PleatMesh *base;
    size_t nv, nt, ne;
    double *omega, *zeta, *amp, *corner;
} Input;

static Input make_input(void) {
    Input in;
    double k[3] = {3, 4, 0};
    uint32_t t[3 * 18];
    double *x;
    size_t i;
    in.base = make_grid(N);
    in.nv = pleat_mesh_vertex_count(in.base);
    in.nt = pleat_mesh_triangle_count(in.base);
    in.zeta = filled(2 * in.nv, 0);
    in.omega = plane_wave(in.base, k, &in.ne, in.zeta);
    in.amp = filled(in.nv, 0.1);
    in.corner = filled(3 * in.nt, 0);
    x = positions_of(in.base);
    pleat_mesh_copy_indices(in.base, t, 3 * 18);
    for (i = 0; i < 3 * in.nt; i++) {
        const double *a = x + 3 * t[i], *b = x + 3 * t[i - i % 3 + (i % 3 + 1) % 3];
        in.corner[i] = k[0] * (b[0] - a[0]) + k[1] * (b[1] - a[1]);
    }
    free(x);
    return in;
}

static void free_input(Input *in) {
    pleat_mesh_destroy(in->base);
    free(in->omega), free(in->zeta), free(in->amp), free(in->corner);
}

static void misuse_create(Input *in) {
    PleatCwf *c = NULL;
    PleatMesh *b = in->base;
    size_t nv = in->nv, ne = in->ne, nc = 3 * in->nt;
    double bad[64];
    /* NULL pointers (zeta NULL is allowed: Knoppel) */
    CHECK_STATUS(pleat_cwf_create(NULL, in->omega, ne, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, NULL, ne, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, NULL, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, in->amp, in->zeta, nv, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* wrong counts */
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne - 1, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne + 1, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, in->amp, in->zeta, nv - 1, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create(b, in->omega, (size_t)-1, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, in->corner, nc - 3, in->amp, NULL, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, in->corner, in->ne, in->amp, NULL, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* NaN / Inf / negative values */
    memcpy(bad, in->omega, ne * sizeof *bad);
    bad[5] = NAN;
    CHECK_STATUS(pleat_cwf_create(b, bad, ne, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    bad[5] = -INFINITY;
    CHECK_STATUS(pleat_cwf_create(b, bad, ne, in->amp, NULL, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    memcpy(bad, in->amp, nv * sizeof *bad);
    bad[3] = -0.5;
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, bad, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    bad[3] = NAN;
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, bad, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    memcpy(bad, in->zeta, 2 * nv * sizeof *bad);
    bad[2 * nv - 1] = NAN;
    CHECK_STATUS(pleat_cwf_create(b, in->omega, ne, in->amp, bad, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    memcpy(bad, in->corner, nc * sizeof *bad);
    bad[7] = NAN;
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, bad, nc, in->amp, NULL, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* antisymmetry: corner 0 of triangle 0 is edge (0,1) on the boundary (one triangle: any
       value is fine); corner 1 of triangle 0 is edge (1,5), shared with triangle 3 */
    memcpy(bad, in->corner, nc * sizeof *bad);
    bad[0] += 100.0;
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, bad, nc, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_OK);
    pleat_cwf_destroy(c);
    c = NULL;
    bad[1] += 1e-3;
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, bad, nc, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    bad[1] -= 1e-3 - 1e-9; /* within PLEAT_CORNER_OMEGA_TOLERANCE */
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, bad, nc, in->amp, in->zeta, nv, &c),
                 PLEAT_STATUS_OK);
    pleat_cwf_destroy(c);
    c = NULL;
    /* symmetric instead of antisymmetric on every interior edge (a common sign mistake) */
    {
        size_t i;
        for (i = 0; i < nc; i++) bad[i] = fabs(in->corner[i]);
        CHECK_STATUS(pleat_cwf_create_from_corner_omega(b, bad, nc, in->amp, NULL, nv, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
    }
    /* frequency: counts, location, NaN, parameters */
    {
        double kv[3 * 18];
        PleatKnoppelParams kp = pleat_knoppel_params_default();
        size_t i;
        for (i = 0; i < 3 * 18; i++) kv[i] = (i % 3 == 0) ? 2.0 : 0.0;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv - 1, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, NULL, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_FACE, in->amp,
                                                     nv, NULL, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, 7, in->amp, nv, NULL, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, NULL, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, NULL, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        kv[4] = NAN;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, NULL, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        kv[4] = 0;
        kp.max_iterations = 0;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, &kp, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        kp = pleat_knoppel_params_default();
        kp.weights = 9;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, &kp, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        kp = pleat_knoppel_params_default();
        kp.tolerance = NAN;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, &kp, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        kp = pleat_knoppel_params_default();
        kp.struct_size = 0;
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, &kp, &c),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        /* an older, shorter struct: the missing fields take their defaults */
        kp = pleat_knoppel_params_default();
        kp.struct_size = 8;
        kp.max_iterations = 0; /* beyond struct_size: ignored */
        CHECK_STATUS(pleat_cwf_create_from_frequency(b, kv, nv, PLEAT_FREQUENCY_PER_VERTEX,
                                                     in->amp, nv, &kp, &c),
                     PLEAT_STATUS_OK);
        pleat_cwf_destroy(c);
        c = NULL;
    }
    CHECK(c == NULL); /* outputs are written only on success */
}

static void misuse_bad_base(void) {
    /* three triangles on edge (0,1): non-manifold */
    static const double p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
    static const uint32_t nonmanifold[] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    /* two triangles traversing edge (0,1) in the same direction: misoriented */
    static const uint32_t misoriented[] = {0, 1, 2, 0, 1, 3};
    PleatMesh *m = NULL;
    PleatCwf *c = NULL;
    double w[16] = {0}, a[5] = {0.1, 0.1, 0.1, 0.1, 0.1}, corner[9] = {0};
    size_t ne;
    CHECK_STATUS(pleat_mesh_create_f64(p, 5, 0, nonmanifold, 9, &m), PLEAT_STATUS_OK);
    ne = pleat_mesh_edge_count(m);
    CHECK(ne == 7);
    CHECK_STATUS(pleat_cwf_create(m, w, ne, a, NULL, 5, &c), PLEAT_STATUS_INVALID_MESH);
    /* the base-mesh problem is reported before an antisymmetry violation */
    corner[0] = 1.0;
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(m, corner, 9, a, NULL, 5, &c),
                 PLEAT_STATUS_INVALID_MESH);
    pleat_mesh_destroy(m);
    m = NULL;
    CHECK_STATUS(pleat_mesh_create_f64(p, 5, 0, misoriented, 6, &m), PLEAT_STATUS_OK);
    ne = pleat_mesh_edge_count(m);
    CHECK_STATUS(pleat_cwf_create(m, w, ne, a, NULL, 5, &c), PLEAT_STATUS_INVALID_MESH);
    pleat_mesh_destroy(m);
    CHECK(c == NULL);
}

static void misuse_evaluate(Input *in) {
    PleatCwf *c = NULL;
    PleatMesh *out = NULL;
    PleatWrinkleFields *f = NULL;
    PleatWrinkleEvalParams p = pleat_wrinkle_eval_params_default();
    PleatWrinkleEvalStats s;
    memset(&s, 0, sizeof s);
    CHECK_STATUS(pleat_cwf_create(in->base, in->omega, in->ne, in->amp, in->zeta, in->nv, &c),
                 PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_cwf_evaluate(NULL, NULL, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_evaluate(c, NULL, NULL, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* stats without struct_size */
    CHECK_STATUS(pleat_cwf_evaluate(c, NULL, NULL, NULL, &out, NULL, &s),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* levels too large: refused before allocating anything */
    p.levels = 12; /* 18 * 4^12 = 302 M triangles > 2^26 */
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    p.levels = 40;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    p.levels = 0xffffffffu;
    p.max_output_triangles = (uint64_t)-1;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    p = pleat_wrinkle_eval_params_default();
    p.max_output_triangles = 18 * 16 - 1; /* level 2 gives 18 * 16 */
    p.levels = 2;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    p.max_output_triangles = 0;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* bad parameters */
    p = pleat_wrinkle_eval_params_default();
    p.struct_size = 4;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_wrinkle_eval_params_default();
    p.flags = 0x100;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, &f, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_wrinkle_eval_params_default();
    p.boundary = 2;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_wrinkle_eval_params_default();
    p.displacement_scale = NAN;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_wrinkle_eval_params_default();
    p.corner_angle = 4.0;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(out == NULL && f == NULL);
    /* an older caller knowing only struct_size and levels */
    p = pleat_wrinkle_eval_params_default();
    p.struct_size = 8;
    p.levels = 1;
    p.displacement_scale = NAN; /* beyond struct_size: not read */
    s.struct_size = 16;         /* only struct_size, levels and vertex_count */
    s.triangle_count = 12345;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, NULL, &s), PLEAT_STATUS_OK);
    CHECK(s.struct_size == 16 && s.levels == 1 && s.vertex_count == pleat_mesh_vertex_count(out));
    CHECK(s.triangle_count == 12345 && pleat_mesh_triangle_count(out) == 4 * 18);
    pleat_mesh_destroy(out);
    out = NULL;

    /* fields: not requested, unknown, too small, bad stride */
    p = pleat_wrinkle_eval_params_default();
    p.levels = 1;
    p.flags = PLEAT_WRINKLE_FIELD_PHASE;
    CHECK_STATUS(pleat_cwf_evaluate(c, &p, NULL, NULL, &out, &f, NULL), PLEAT_STATUS_OK);
    {
        size_t n = pleat_mesh_vertex_count(out);
        double *buf = filled(3 * n, 0);
        CHECK(pleat_wrinkle_fields_count(f, PLEAT_WRINKLE_FIELD_PHASE) == n);
        CHECK(pleat_wrinkle_fields_count(f, PLEAT_WRINKLE_FIELD_Z) == 0);
        CHECK(pleat_wrinkle_fields_count(f, 3) == 0 && pleat_wrinkle_fields_count(NULL, 2) == 0);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_Z, buf, n, 0),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, 3, buf, n, 0), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_PHASE, buf, n - 1, 0),
                     PLEAT_STATUS_LIMIT_EXCEEDED);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_PHASE, buf, n, 4),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_PHASE, buf, n, (size_t)-1 / 2),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_PHASE, NULL, n, 0),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(NULL, PLEAT_WRINKLE_FIELD_PHASE, buf, n, 0),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_wrinkle_fields_copy(f, PLEAT_WRINKLE_FIELD_PHASE, buf, n, 0),
                     PLEAT_STATUS_OK);
        free(buf);
    }
    pleat_wrinkle_fields_destroy(f);
    pleat_wrinkle_fields_destroy(NULL);
    pleat_mesh_destroy(out);

    /* copy-out of the field */
    {
        double buf[2 * 64];
        PleatKnoppelReport r;
        CHECK_STATUS(pleat_cwf_copy_omega(c, buf, in->ne - 1), PLEAT_STATUS_LIMIT_EXCEEDED);
        CHECK_STATUS(pleat_cwf_copy_omega(c, NULL, in->ne), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_copy_omega(NULL, buf, in->ne), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_copy_amplitude(c, buf, in->nv - 1), PLEAT_STATUS_LIMIT_EXCEEDED);
        CHECK_STATUS(pleat_cwf_copy_zeta(c, buf, in->nv - 1), PLEAT_STATUS_LIMIT_EXCEEDED);
        CHECK_STATUS(pleat_cwf_copy_zeta(c, buf, (size_t)-1 / 2 + 1),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_copy_corner_omega(c, buf, 3 * in->nt - 1),
                     PLEAT_STATUS_LIMIT_EXCEEDED);
        r.struct_size = 0;
        CHECK_STATUS(pleat_cwf_get_knoppel_report(c, &r), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_get_knoppel_report(c, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK(pleat_cwf_vertex_count(NULL) == 0 && pleat_cwf_edge_count(NULL) == 0);
    }

    /* files */
    {
        PleatCwf *r = NULL;
        CHECK_STATUS(pleat_cwf_read_file(in->base, "assets/no_such_file.cwf", &r), PLEAT_STATUS_IO);
        CHECK_STATUS(pleat_cwf_read_file(in->base, NULL, &r), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_read_file(NULL, "x.cwf", &r), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_read_file(in->base, "assets/dirty_two_boxes.obj", &r),
                     PLEAT_STATUS_PARSE);
        CHECK_STATUS(pleat_cwf_write_file(c, "/no/such/dir/x.cwf"), PLEAT_STATUS_IO);
        CHECK_STATUS(pleat_cwf_write_file(NULL, "x.cwf"), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_write_file(c, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK(r == NULL);
    }
    pleat_cwf_destroy(c);
    pleat_cwf_destroy(NULL);
}

static void unsupported(Input *in) {
    PleatCwf *c = NULL;
    PleatMesh *out = NULL;
    printf("SKIPPED: this pleat was built without \"wrinkle\"; checking UNSUPPORTED\n");
    CHECK_STATUS(pleat_cwf_create(in->base, in->omega, in->ne, in->amp, in->zeta, in->nv, &c),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_create_from_corner_omega(in->base, in->corner, 3 * in->nt, in->amp,
                                                    NULL, in->nv, &c),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_create_from_frequency(in->base, in->omega, in->nv,
                                                 PLEAT_FREQUENCY_PER_VERTEX, in->amp, in->nv,
                                                 NULL, &c),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_evaluate(c, NULL, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_copy_omega(c, in->omega, in->ne), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_write_file(c, "x.cwf"), PLEAT_STATUS_UNSUPPORTED);
    CHECK(c == NULL && out == NULL);
    CHECK(pleat_wrinkle_eval_params_default().levels == 3); /* plain data: in every build */
}

int main(void) {
    Input in;
    misuse_edges();
    in = make_input();
    if (pleat_has_feature("wrinkle")) {
        misuse_create(&in);
        misuse_bad_base();
        misuse_evaluate(&in);
    } else {
        unsupported(&in);
    }
    free_input(&in);
    return finish("wrinkle_misuse");
}
