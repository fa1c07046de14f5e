/* Complex wrinkle fields from C: a plane wave on a flat grid (exact phase after refinement),
   the same wave through per-corner omega, a closed base (watertight output), a vortex, the
   Knoppel phase, .cwf files, and cancellation through the progress callback.
   Skips (and checks PLEAT_STATUS_UNSUPPORTED) when the library was built without "wrinkle". */
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>
#include "wrinkle_util.h"

static const double K[3] = {23.0, 9.0, 0.0}; /* radians per unit length */
static const double AMP = 0.01;

static PleatWrinkleEvalStats new_stats(void) {
    PleatWrinkleEvalStats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    return s;
}

static void check_report(const PleatMesh *m, int want_closed) {
    PleatMeshReport r;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_OK);
    printf("  output: V=%llu F=%llu manifold=%u closed=%u watertight=%u oriented=%u "
           "self_intersection_free=%u\n",
           (unsigned long long)r.vertex_count, (unsigned long long)r.triangle_count,
           r.is_manifold, r.is_closed, r.is_watertight, r.consistently_oriented,
           r.self_intersection_free);
    CHECK(r.is_manifold == 1 && r.consistently_oriented == 1 && r.component_count == 1);
    CHECK(r.is_watertight == (uint32_t)want_closed);
    CHECK(r.self_intersection_free == 1); /* small amplitude: no fold-over */
}

/* Plane wave on a flat 9x9 grid, evaluated at level 3 with every field requested. */
static void plane_wave_on_grid(void) {
    PleatMesh *base = make_grid(9), *out = NULL;
    size_t nv = pleat_mesh_vertex_count(base), nt = pleat_mesh_triangle_count(base), ne, i;
    double *zeta = (double *)malloc(2 * nv * sizeof *zeta);
    double *omega = plane_wave(base, K, &ne, zeta);
    double *amp = filled(nv, AMP);
    PleatCwf *cwf = NULL;
    PleatWrinkleFields *fields = NULL;
    PleatWrinkleEvalParams params = pleat_wrinkle_eval_params_default();
    PleatWrinkleEvalStats stats = new_stats();
    printf("plane wave on a %zu-vertex grid (%zu edges)\n", nv, ne);
    CHECK(ne == 8 * 9 * 2 + 64); /* horizontal + vertical + diagonal edges */
    CHECK_STATUS(pleat_cwf_create(base, omega, ne, amp, zeta, nv, &cwf), PLEAT_STATUS_OK);
    CHECK(pleat_cwf_vertex_count(cwf) == nv && pleat_cwf_edge_count(cwf) == ne);
    params.levels = 3;
    params.flags = PLEAT_WRINKLE_FIELD_PHASE | PLEAT_WRINKLE_FIELD_Z | PLEAT_WRINKLE_FIELD_NORMALS |
                   PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS | PLEAT_WRINKLE_FIELD_AMPLITUDE;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, NULL, NULL, &out, &fields, &stats),
                 PLEAT_STATUS_OK);
    if (out && fields) {
        size_t n = pleat_mesh_vertex_count(out);
        double *x = positions_of(out);
        double *phase = filled(n, 0), *z = filled(2 * n, 0), *nrm = filled(3 * n, 0);
        double *smooth = filled(3 * n, 0), *a = filled(n, 0);
        double phase_err = 0, mod_err = 0, disp_err = 0, amp_err = 0;
        printf("  stats: levels %u, V=%llu F=%llu, %.4f s (subdivision %.4f s, displacement "
               "%.4f s)\n",
               stats.levels, (unsigned long long)stats.vertex_count,
               (unsigned long long)stats.triangle_count, stats.total_seconds,
               stats.subdivision_seconds, stats.displacement_seconds);
        CHECK(stats.struct_size == sizeof stats && stats.levels == 3);
        CHECK(stats.triangle_count == 64 * nt && stats.vertex_count == n);
        CHECK(pleat_mesh_triangle_count(out) == 64 * nt);
        CHECK(pleat_wrinkle_fields_count(fields, PLEAT_WRINKLE_FIELD_PHASE) == n);
        CHECK(pleat_wrinkle_fields_count(fields, PLEAT_WRINKLE_FIELD_OMEGA) == 0);
        CHECK_STATUS(pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_PHASE, phase, n, 0),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_Z, z, n, 0),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_NORMALS, nrm, n, 0),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(
            pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS, smooth, n, 0),
            PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_AMPLITUDE, a, n, 0),
                     PLEAT_STATUS_OK);
        for (i = 0; i < n; i++) {
            /* the refined plane wave is exact on a flat mesh: arg z = k.x at the smooth
               (undisplaced) position, |z| = a */
            double e = fabs(wrap_pi(phase[i] - dot3(K, smooth + 3 * i)));
            double m = fabs(hypot(z[2 * i], z[2 * i + 1]) - AMP) / AMP;
            int c;
            phase_err = e > phase_err ? e : phase_err;
            mod_err = m > mod_err ? m : mod_err;
            amp_err = fabs(a[i] - AMP) > amp_err ? fabs(a[i] - AMP) : amp_err;
            /* output = smooth + Re(z) n */
            for (c = 0; c < 3; c++) {
                double d = fabs(x[3 * i + c] - (smooth[3 * i + c] + z[2 * i] * nrm[3 * i + c]));
                disp_err = d > disp_err ? d : disp_err;
            }
        }
        printf("  plane wave: max |arg z - k.x| = %.2e, max ||z| - a|/a = %.2e, displacement "
               "residual %.2e\n",
               phase_err, mod_err, disp_err);
        CHECK(phase_err < 1e-9 && mod_err < 1e-9 && disp_err < 1e-15 && amp_err < 1e-15);
        CHECK(fabs(nrm[2] - 1.0) < 1e-15); /* flat grid: normals +z */

        /* float copy into an interleaved vertex buffer: 8 floats per vertex, normal at 3..5 */
        {
            float *vb = (float *)malloc(8 * n * sizeof *vb);
            for (i = 0; i < 8 * n; i++) vb[i] = -7.0f;
            CHECK_STATUS(pleat_wrinkle_fields_copy_f32(fields, PLEAT_WRINKLE_FIELD_NORMALS,
                                                       vb + 3, n, 8 * sizeof(float)),
                         PLEAT_STATUS_OK);
            CHECK(vb[3] == (float)nrm[0] && vb[5] == (float)nrm[2] && vb[8 * (n - 1) + 5] == 1.0f);
            CHECK(vb[0] == -7.0f && vb[6] == -7.0f && vb[8 * n - 1] == -7.0f);
            free(vb);
        }
        free(x), free(phase), free(z), free(nrm), free(smooth), free(a);
    }
    check_report(out, 0);
    pleat_mesh_destroy(out);
    pleat_wrinkle_fields_destroy(fields);

    /* the fine one-form: on the output mesh's edges, still k.(x_j - x_i) at smooth positions */
    out = NULL;
    fields = NULL;
    params.levels = 2;
    params.flags = PLEAT_WRINKLE_FIELD_OMEGA | PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, NULL, NULL, &out, &fields, NULL),
                 PLEAT_STATUS_OK);
    if (out && fields) {
        size_t fe, n = pleat_mesh_vertex_count(out), bad = 0;
        uint32_t *e = edges_of(out, &fe);
        double *w = filled(fe, 0), *s = filled(3 * n, 0);
        CHECK(pleat_wrinkle_fields_count(fields, PLEAT_WRINKLE_FIELD_OMEGA) == fe);
        CHECK_STATUS(pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_OMEGA, w, fe, 0),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(
            pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS, s, n, 0),
            PLEAT_STATUS_OK);
        for (i = 0; i < fe; i++) {
            const double *p = s + 3 * e[2 * i], *q = s + 3 * e[2 * i + 1];
            double d[3];
            d[0] = q[0] - p[0], d[1] = q[1] - p[1], d[2] = q[2] - p[2];
            bad += fabs(w[i] - dot3(K, d)) > 1e-9;
        }
        printf("  level-2 one-form on %zu edges: %zu off the plane wave\n", fe, bad);
        CHECK(bad == 0);
        free(e), free(w), free(s);
    }
    pleat_mesh_destroy(out);
    pleat_wrinkle_fields_destroy(fields);

    /* the same field through per-corner omega: callers need not know the edge numbering */
    {
        double *corner = filled(3 * nt, 0), *x = positions_of(base), *w2 = filled(ne, 0);
        uint32_t *t = (uint32_t *)malloc(3 * nt * sizeof *t);
        PleatCwf *c2 = NULL;
        double maxdiff = 0;
        pleat_mesh_copy_indices(base, t, 3 * nt);
        for (i = 0; i < 3 * nt; i++) {
            size_t f = i / 3, c = i % 3;
            const double *a = x + 3 * t[3 * f + c], *b = x + 3 * t[3 * f + (c + 1) % 3];
            double d[3];
            d[0] = b[0] - a[0], d[1] = b[1] - a[1], d[2] = b[2] - a[2];
            corner[i] = dot3(K, d);
        }
        CHECK_STATUS(pleat_cwf_create_from_corner_omega(base, corner, 3 * nt, amp, zeta, nv, &c2),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_cwf_copy_omega(c2, w2, ne), PLEAT_STATUS_OK);
        for (i = 0; i < ne; i++)
            maxdiff = fabs(w2[i] - omega[i]) > maxdiff ? fabs(w2[i] - omega[i]) : maxdiff;
        printf("  corner omega -> edge omega: max difference %.2e\n", maxdiff);
        CHECK(maxdiff < 1e-14);
        /* and back */
        {
            double *back = filled(3 * nt, 0), md = 0;
            CHECK_STATUS(pleat_cwf_copy_corner_omega(c2, back, 3 * nt), PLEAT_STATUS_OK);
            for (i = 0; i < 3 * nt; i++)
                md = fabs(back[i] - corner[i]) > md ? fabs(back[i] - corner[i]) : md;
            CHECK(md < 1e-14);
            free(back);
        }
        pleat_cwf_destroy(c2);
        free(corner), free(x), free(w2), free(t);
    }

    /* Knoppel from wave vectors: the recovered phase differs from k.x by a global constant */
    {
        double *k = (double *)malloc(3 * nv * sizeof *k), *zt = filled(2 * nv, 0);
        PleatCwf *c3 = NULL;
        PleatKnoppelReport kr;
        double err = 0;
        uint32_t *e = edges_of(base, &ne);
        for (i = 0; i < nv; i++) k[3 * i] = K[0], k[3 * i + 1] = K[1], k[3 * i + 2] = K[2];
        CHECK_STATUS(pleat_cwf_create_from_frequency(base, k, nv, PLEAT_FREQUENCY_PER_VERTEX, amp,
                                                     nv, NULL, &c3),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_cwf_copy_zeta(c3, zt, nv), PLEAT_STATUS_OK);
        for (i = 0; i < ne; i++) {
            uint32_t a = e[2 * i], b = e[2 * i + 1];
            double d = atan2(zt[2 * b + 1], zt[2 * b]) - atan2(zt[2 * a + 1], zt[2 * a]);
            double r = fabs(wrap_pi(d - omega[i]));
            err = r > err ? r : err;
        }
        memset(&kr, 0, sizeof kr);
        kr.struct_size = sizeof kr;
        CHECK_STATUS(pleat_cwf_get_knoppel_report(c3, &kr), PLEAT_STATUS_OK);
        printf("  Knoppel: %u iterations, eigenvalue %.2e, residual %.2e; max phase-difference "
               "error %.2e\n",
               kr.iterations, kr.eigenvalue, kr.residual, err);
        CHECK(kr.iterations >= 1 && kr.eigenvalue < 1e-6 && err < 1e-6);
        pleat_cwf_destroy(c3);
        /* per-face wave vectors */
        c3 = NULL;
        {
            double *kf = (double *)malloc(3 * nt * sizeof *kf);
            PleatKnoppelParams kp = pleat_knoppel_params_default();
            kp.weights = PLEAT_PHASE_WEIGHTS_EDGE_AREA;
            for (i = 0; i < nt; i++)
                kf[3 * i] = K[0], kf[3 * i + 1] = K[1], kf[3 * i + 2] = K[2];
            CHECK_STATUS(pleat_cwf_create_from_frequency(base, kf, nt, PLEAT_FREQUENCY_PER_FACE,
                                                         amp, nv, &kp, &c3),
                         PLEAT_STATUS_OK);
            free(kf);
        }
        pleat_cwf_destroy(c3);
        free(k), free(zt), free(e);
    }

    /* .cwf round trip, bit for bit */
    {
        char path[] = "/tmp/pleat_wrinkle_eval_XXXXXX";
        int fd = mkstemp(path);
        PleatCwf *back = NULL;
        PleatMesh *octa = make_octahedron();
        CHECK(fd >= 0);
        if (fd >= 0) close(fd);
        CHECK_STATUS(pleat_cwf_write_file(cwf, path), PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_cwf_read_file(base, path, &back), PLEAT_STATUS_OK);
        if (back) {
            double *w = filled(ne, 0), *a = filled(nv, 0), *z = filled(2 * nv, 0);
            PleatKnoppelReport kr;
            CHECK_STATUS(pleat_cwf_copy_omega(back, w, ne), PLEAT_STATUS_OK);
            CHECK_STATUS(pleat_cwf_copy_amplitude(back, a, nv), PLEAT_STATUS_OK);
            CHECK_STATUS(pleat_cwf_copy_zeta(back, z, nv), PLEAT_STATUS_OK);
            CHECK(memcmp(w, omega, ne * sizeof *w) == 0);
            CHECK(memcmp(a, amp, nv * sizeof *a) == 0);
            CHECK(memcmp(z, zeta, 2 * nv * sizeof *z) == 0);
            memset(&kr, 0, sizeof kr);
            kr.struct_size = sizeof kr;
            /* a field read from a file has no Knoppel report */
            CHECK_STATUS(pleat_cwf_get_knoppel_report(back, &kr), PLEAT_STATUS_INVALID_ARGUMENT);
            free(w), free(a), free(z);
        }
        pleat_cwf_destroy(back);
        back = NULL;
        /* written for another base mesh */
        CHECK_STATUS(pleat_cwf_read_file(octa, path, &back), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK(back == NULL);
        remove(path);
        pleat_mesh_destroy(octa);
    }
    pleat_cwf_destroy(cwf);
    pleat_mesh_destroy(base);
    free(zeta), free(omega), free(amp);
}

/* A closed base: the output is watertight. A global wave on a closed surface. */
static void closed_base(void) {
    PleatMesh *base = make_octahedron(), *out = NULL;
    size_t nv = pleat_mesh_vertex_count(base), ne;
    double k[3] = {2.0, 1.0, 3.0};
    double *zeta = filled(2 * nv, 0), *omega = plane_wave(base, k, &ne, zeta);
    double *amp = filled(nv, 0.02);
    PleatCwf *cwf = NULL;
    PleatWrinkleEvalStats stats = new_stats();
    PleatWrinkleEvalParams params = pleat_wrinkle_eval_params_default(); /* levels 3 */
    printf("octahedron (closed)\n");
    CHECK(ne == 12);
    CHECK_STATUS(pleat_cwf_create(base, omega, ne, amp, zeta, nv, &cwf), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, NULL, NULL, &out, NULL, &stats),
                 PLEAT_STATUS_OK);
    CHECK(stats.triangle_count == 8 * 64);
    check_report(out, 1);
    pleat_mesh_destroy(out);
    /* zero levels: the displaced base itself */
    out = NULL;
    params.levels = 0;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, NULL, NULL, &out, NULL, NULL), PLEAT_STATUS_OK);
    CHECK(pleat_mesh_triangle_count(out) == 8 && pleat_mesh_vertex_count(out) == 6);
    pleat_mesh_destroy(out);
    pleat_cwf_destroy(cwf);
    pleat_mesh_destroy(base);
    free(zeta), free(omega), free(amp);
}

/* A vortex (winding number 1 around a point inside a triangle): finite everywhere. */
static void vortex(void) {
    PleatMesh *base = make_grid(9), *out = NULL;
    size_t nv = pleat_mesh_vertex_count(base), ne, i;
    double *x = positions_of(base);
    uint32_t *e = edges_of(base, &ne);
    double *omega = filled(ne, 0), *zeta = filled(2 * nv, 0), *amp = filled(nv, 0.02);
    double cx = 0.5 + 0.125 / 3, cy = 0.5 + 0.125 / 5;
    PleatCwf *cwf = NULL, *knoppel = NULL;
    PleatWrinkleFields *fields = NULL;
    PleatWrinkleEvalParams params = pleat_wrinkle_eval_params_default();
    printf("vortex\n");
    for (i = 0; i < nv; i++) {
        double th = atan2(x[3 * i + 1] - cy, x[3 * i] - cx);
        zeta[2 * i] = cos(th), zeta[2 * i + 1] = sin(th);
    }
    for (i = 0; i < ne; i++) {
        uint32_t a = e[2 * i], b = e[2 * i + 1];
        omega[i] = wrap_pi(atan2(x[3 * b + 1] - cy, x[3 * b] - cx) -
                           atan2(x[3 * a + 1] - cy, x[3 * a] - cx));
    }
    CHECK_STATUS(pleat_cwf_create(base, omega, ne, amp, zeta, nv, &cwf), PLEAT_STATUS_OK);
    params.flags = PLEAT_WRINKLE_FIELD_PHASE | PLEAT_WRINKLE_FIELD_Z;
    params.boundary = PLEAT_WRINKLE_BOUNDARY_SMOOTH;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, NULL, NULL, &out, &fields, NULL),
                 PLEAT_STATUS_OK);
    if (out && fields) {
        size_t n = pleat_mesh_vertex_count(out), bad = 0;
        double *p = positions_of(out), *z = filled(2 * n, 0), zmin = 1e300;
        pleat_wrinkle_fields_copy(fields, PLEAT_WRINKLE_FIELD_Z, z, n, 0);
        for (i = 0; i < 3 * n; i++) bad += !isfinite(p[i]);
        for (i = 0; i < n; i++) {
            double m = hypot(z[2 * i], z[2 * i + 1]);
            bad += !isfinite(m);
            zmin = m < zmin ? m : zmin;
        }
        printf("  %zu vertices, %zu non-finite values, min |z| = %.3g (amplitude 0.02)\n", n, bad,
               zmin);
        CHECK(bad == 0 && zmin < 0.01); /* |z| dips towards the singularity */
        check_report(out, 0);
        free(p), free(z);
    }
    /* Knoppel's phase for the vortex one-form (zeta NULL) */
    CHECK_STATUS(pleat_cwf_create(base, omega, ne, amp, NULL, nv, &knoppel), PLEAT_STATUS_OK);
    {
        PleatKnoppelReport kr;
        PleatMesh *o2 = NULL;
        memset(&kr, 0, sizeof kr);
        kr.struct_size = sizeof kr;
        CHECK_STATUS(pleat_cwf_get_knoppel_report(knoppel, &kr), PLEAT_STATUS_OK);
        printf("  Knoppel on the vortex: eigenvalue %.3g after %u iterations\n", kr.eigenvalue,
               kr.iterations);
        /* the wrapped one-form has holonomy 2 pi around the centre: flat connection, tiny
           eigenvalue; the point is that everything stays finite */
        CHECK(isfinite(kr.eigenvalue) && isfinite(kr.residual));
        CHECK_STATUS(pleat_cwf_evaluate(knoppel, NULL, NULL, NULL, &o2, NULL, NULL),
                     PLEAT_STATUS_OK);
        pleat_mesh_destroy(o2);
    }
    pleat_cwf_destroy(knoppel);
    pleat_wrinkle_fields_destroy(fields);
    pleat_mesh_destroy(out);
    pleat_cwf_destroy(cwf);
    pleat_mesh_destroy(base);
    free(x), free(e), free(omega), free(zeta), free(amp);
}

typedef struct {
    int calls;
    int cancel_at; /* cancel on this call (1-based); 0 = never */
    double last;
    int monotone;
} Progress;

static int32_t on_progress(void *user, const PleatProgress *info) {
    Progress *p = (Progress *)user;
    p->calls++;
    if (info->fraction < p->last || !info->stage) p->monotone = 0;
    p->last = info->fraction;
    return p->cancel_at != 0 && p->calls >= p->cancel_at;
}

static void progress_and_cancel(void) {
    PleatMesh *base = make_grid(5), *out = NULL;
    size_t nv = pleat_mesh_vertex_count(base), ne;
    double *zeta = filled(2 * nv, 0), *omega = plane_wave(base, K, &ne, zeta);
    double *amp = filled(nv, AMP);
    PleatCwf *cwf = NULL;
    PleatWrinkleFields *fields = NULL;
    PleatWrinkleEvalParams params = pleat_wrinkle_eval_params_default();
    PleatWrinkleEvalStats stats = new_stats();
    Progress pr = {0, 0, 0.0, 1};
    printf("progress and cancellation\n");
    CHECK_STATUS(pleat_cwf_create(base, omega, ne, amp, zeta, nv, &cwf), PLEAT_STATUS_OK);
    params.levels = 4;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, on_progress, &pr, &out, NULL, NULL),
                 PLEAT_STATUS_OK);
    printf("  %d progress calls, last fraction %g\n", pr.calls, pr.last);
    /* per level: 5 parts (4 on the last) and the level; then the displacement */
    CHECK(pr.calls == 4 * 6 && pr.last == 1.0 && pr.monotone);
    pleat_mesh_destroy(out);
    out = NULL;
    /* cancel after the second level: no output is written, the stats stay untouched */
    pr.calls = 0, pr.cancel_at = 2, pr.last = 0;
    params.flags = PLEAT_WRINKLE_FIELD_PHASE;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, on_progress, &pr, &out, &fields, &stats),
                 PLEAT_STATUS_CANCELLED);
    CHECK(pr.calls == 2 && out == NULL && fields == NULL && stats.levels == 0);
    /* also from a custom thread pool: the callback still runs on this thread */
    CHECK_STATUS(pleat_set_thread_count(2), PLEAT_STATUS_OK);
    pr.calls = 0;
    CHECK_STATUS(pleat_cwf_evaluate(cwf, &params, on_progress, &pr, &out, NULL, NULL),
                 PLEAT_STATUS_CANCELLED);
    /* the worker waits for each answer, so it stops at exactly the report that asked */
    CHECK(pr.calls == 2 && out == NULL);
    CHECK_STATUS(pleat_set_thread_count(0), PLEAT_STATUS_OK);
    pleat_cwf_destroy(cwf);
    pleat_mesh_destroy(base);
    free(zeta), free(omega), free(amp);
}

/* Without the capability every wrinkle function answers UNSUPPORTED; the edge list works. */
static void unsupported(void) {
    PleatMesh *base = make_grid(3), *out = NULL;
    PleatCwf *cwf = NULL;
    double w[16] = {0}, a[9] = {0};
    size_t ne = pleat_mesh_edge_count(base);
    printf("SKIPPED: this pleat was built without \"wrinkle\"; checking UNSUPPORTED\n");
    CHECK(ne == 16);
    CHECK_STATUS(pleat_cwf_create(base, w, ne, a, NULL, 9, &cwf), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_evaluate(cwf, NULL, NULL, NULL, &out, NULL, NULL),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_read_file(base, "x.cwf", &cwf), PLEAT_STATUS_UNSUPPORTED);
    CHECK(cwf == NULL && out == NULL && pleat_cwf_vertex_count(cwf) == 0);
    pleat_cwf_destroy(cwf);
    pleat_mesh_destroy(base);
}

int main(void) {
    if (!pleat_has_feature("wrinkle")) {
        unsupported();
        return finish("wrinkle_eval");
    }
    plane_wave_on_grid();
    closed_base();
    vortex();
    progress_and_cancel();
    return finish("wrinkle_eval");
}
