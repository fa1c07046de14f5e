/* Wrinkle design and region edits through the C ABI (dissertation ch. 3.6):
   grow a region, rotate the wrinkles in it, check the fixed part is copied bit for bit, an
   identity edit returns the input, design from a source, evaluate the edited keyframe, and
   misuse answers a status with a message; the adaptive interface width (compat_target) and the
   edit report; a caller compiled before edit_weight / compat_target / max_interface_rings were
   appended keeps working. Without the "wrinkle" capability every call answers
   PLEAT_STATUS_UNSUPPORTED (checked). */
#include <stddef.h>
#include "wrinkle_util.h"

#define N 21

/* Per vertex of the N x N grid: 1 when every triangle around it is fixed. */
static void fixed_vertices(const uint8_t *labels, uint8_t *fixed) {
    size_t nv = (size_t)N * N, f = 0;
    uint8_t *touched = (uint8_t *)calloc(nv, 1);
    int i, j;
    for (j = 0; j + 1 < N; j++)
        for (i = 0; i + 1 < N; i++) {
            uint32_t v00 = (uint32_t)(j * N + i), v10 = v00 + 1, v01 = v00 + N, v11 = v01 + 1;
            uint32_t t[6] = {v00, v10, v11, v00, v11, v01};
            int s, c;
            for (s = 0; s < 2; s++, f++)
                for (c = 0; c < 3; c++)
                    if (labels[f] != PLEAT_FACE_FIXED) touched[t[3 * s + c]] = 1;
        }
    for (f = 0; f < nv; f++) fixed[f] = !touched[f];
    free(touched);
}

/* Counts progress calls; answers "cancel" from call `cancel_at` on (0: never). */
typedef struct {
    int calls, cancel_at;
    const char *stage;
} Calls;

static int count_calls(void *user_data, const PleatProgress *info) {
    Calls *c = (Calls *)user_data;
    c->calls++;
    CHECK(strcmp(info->stage, c->stage) == 0 && info->fraction >= 0 && info->fraction <= 1);
    return c->cancel_at > 0 && c->calls >= c->cancel_at;
}

/* pleat_cwf_design_with_progress / pleat_cwf_edit_with_progress: the same field as
 * without a callback, and a cancel at the first or a middle call gives
 * PLEAT_STATUS_CANCELLED with nothing written (valgrind checks for leaks). */
static void progress_and_cancel(const PleatMesh *m, const PleatCwf *a,
                                const PleatCwfRegionEdit *r, const PleatWrinkleSource *src,
                                const PleatCwf *designed, const PleatCwf *edited, size_t nv,
                                size_t nt) {
    double *x0 = (double *)malloc(2 * nv * sizeof *x0), *x1 = (double *)malloc(2 * nv * sizeof *x1);
    uint8_t *labels = (uint8_t *)malloc(nt);
    Calls c = {0, 0, "design"};
    PleatCwf *out = NULL;
    int k, total;
    CHECK_STATUS(pleat_cwf_design_with_progress(m, src, 1, NULL, NULL, count_calls, &c, &out),
                 PLEAT_STATUS_OK);
    pleat_cwf_copy_zeta(designed, x0, nv);
    pleat_cwf_copy_zeta(out, x1, nv);
    CHECK(c.calls > 3 && memcmp(x0, x1, 2 * nv * sizeof *x0) == 0);
    pleat_cwf_destroy(out);
    out = NULL;
    total = c.calls;
    for (k = 0; k < 2; k++) {
        Calls cc = {0, 0, "design"};
        cc.cancel_at = k == 0 ? 1 : total / 2;
        CHECK_STATUS(pleat_cwf_design_with_progress(m, src, 1, NULL, NULL, count_calls, &cc, &out),
                     PLEAT_STATUS_CANCELLED);
        CHECK(out == NULL && cc.calls == cc.cancel_at);
    }
    CHECK_STATUS(pleat_cwf_design_with_progress(m, src, 1, NULL, NULL, NULL, NULL, &out),
                 PLEAT_STATUS_OK);
    pleat_cwf_destroy(out);
    out = NULL;

    c.calls = 0;
    c.stage = "edit";
    CHECK_STATUS(pleat_cwf_edit_with_progress(a, r, 1, NULL, count_calls, &c, &out, NULL),
                 PLEAT_STATUS_OK);
    pleat_cwf_copy_zeta(edited, x0, nv);
    pleat_cwf_copy_zeta(out, x1, nv);
    CHECK(c.calls > 3 && memcmp(x0, x1, 2 * nv * sizeof *x0) == 0);
    pleat_cwf_destroy(out);
    out = NULL;
    total = c.calls;
    for (k = 0; k < 2; k++) {
        Calls cc = {0, 0, "edit"};
        cc.cancel_at = k == 0 ? 1 : total / 2;
        memset(labels, 0xEE, nt);
        CHECK_STATUS(pleat_cwf_edit_with_progress(a, r, 1, NULL, count_calls, &cc, &out, labels),
                     PLEAT_STATUS_CANCELLED);
        CHECK(out == NULL && cc.calls == cc.cancel_at && labels[0] == 0xEE && labels[nt - 1] == 0xEE);
    }
    free(x0), free(x1), free(labels);
}

/* Misuse of the _with_progress calls themselves: NULL base, field, sources,
 * regions or out, counts beyond the address space, a bad region struct size and a source
 * vertex out of range answer PLEAT_STATUS_INVALID_ARGUMENT with a message naming the
 * argument, before any progress call, and write nothing. */
static void progress_misuse(const PleatMesh *m, const PleatCwf *a, const PleatCwfRegionEdit *r,
                            const PleatWrinkleSource *src, size_t nv, size_t nt) {
    Calls c = {0, 0, "design"};
    PleatCwf *out = NULL;
    PleatWrinkleSource far = *src;
    PleatCwfRegionEdit bad = *r;
    uint8_t *labels = (uint8_t *)malloc(nt);
    far.vertex = (uint32_t)nv;
    bad.struct_size = 1;
    memset(labels, 0xEE, nt);
#define MISUSE(call, what)                                                               \
    do {                                                                                 \
        CHECK_STATUS(call, PLEAT_STATUS_INVALID_ARGUMENT);                               \
        CHECK(strstr(pleat_last_error(), what) != NULL);                                 \
        CHECK(out == NULL && c.calls == 0);                                              \
    } while (0)
    MISUSE(pleat_cwf_design_with_progress(NULL, src, 1, NULL, NULL, count_calls, &c, &out),
           "base");
    MISUSE(pleat_cwf_design_with_progress(m, NULL, 1, NULL, NULL, count_calls, &c, &out),
           "sources");
    MISUSE(pleat_cwf_design_with_progress(m, src, SIZE_MAX, NULL, NULL, count_calls, &c, &out),
           "sources");
    MISUSE(pleat_cwf_design_with_progress(m, &far, 1, NULL, NULL, count_calls, &c, &out),
           "vertex");
    CHECK_STATUS(pleat_cwf_design_with_progress(m, src, 1, NULL, NULL, count_calls, &c, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(pleat_last_error(), "out") != NULL && c.calls == 0);
    c.stage = "edit";
    MISUSE(pleat_cwf_edit_with_progress(NULL, r, 1, NULL, count_calls, &c, &out, labels), "cwf");
    MISUSE(pleat_cwf_edit_with_progress(a, NULL, 1, NULL, count_calls, &c, &out, labels),
           "regions");
    MISUSE(pleat_cwf_edit_with_progress(a, r, SIZE_MAX, NULL, count_calls, &c, &out, labels),
           "regions");
    MISUSE(pleat_cwf_edit_with_progress(a, &bad, 1, NULL, count_calls, &c, &out, labels),
           "struct_size");
    CHECK_STATUS(pleat_cwf_edit_with_progress(a, r, 1, NULL, count_calls, &c, NULL, labels),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(pleat_last_error(), "out") != NULL && c.calls == 0);
    CHECK(labels[0] == 0xEE && labels[nt - 1] == 0xEE);
#undef MISUSE
    free(labels);
}

static void edits(void) {
    const double k[3] = {4 * 2 * M_PI, 0, 0};
    PleatMesh *m = make_grid(N);
    size_t nv = pleat_mesh_vertex_count(m), nt = pleat_mesh_triangle_count(m), ne = 0, i, count = 0;
    double *zeta = (double *)malloc(2 * nv * sizeof *zeta);
    double *omega = plane_wave(m, k, &ne, zeta);
    double *amp = filled(nv, 0.01);
    uint8_t *flags = (uint8_t *)malloc(nt), *labels = (uint8_t *)malloc(nt);
    uint8_t *fixed = (uint8_t *)malloc(nv);
    uint32_t *faces = (uint32_t *)malloc(nt * sizeof *faces);
    uint32_t centre = (N / 2) * N + N / 2;
    PleatCwf *a = NULL, *b = NULL, *c = NULL, *d = NULL;
    PleatCwfRegionEdit r;
    PleatCwfEditParams ep = pleat_cwf_edit_params_default();
    PleatWrinkleSource src;
    double *a0 = (double *)malloc(nv * sizeof *a0), *a1 = (double *)malloc(nv * sizeof *a1);
    double *z0 = (double *)malloc(2 * nv * sizeof *z0), *z1 = (double *)malloc(2 * nv * sizeof *z1);
    double *w0 = (double *)malloc(ne * sizeof *w0), *w1 = (double *)malloc(ne * sizeof *w1);
    int same = 1, n_fixed = 0;

    CHECK_STATUS(pleat_cwf_create(m, omega, ne, amp, zeta, nv, &a), PLEAT_STATUS_OK);
    /* region: the centre vertex's triangles grown to 3 rings */
    CHECK_STATUS(pleat_mesh_grow_faces(m, NULL, 0, &centre, 1, 3, PLEAT_ADJACENCY_VERTEX, flags,
                                       &count),
                 PLEAT_STATUS_OK);
    CHECK(count > 6 && count < nt);
    count = 0;
    for (i = 0; i < nt; i++)
        if (flags[i]) faces[count++] = (uint32_t)i;

    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    r.interface_rings = 3;
    r.faces = faces;
    r.face_count = count;
    r.rotate_radians = M_PI / 2;
    r.frequency_scale = 1.0;
    r.amplitude_scale = 1.0;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &b, labels), PLEAT_STATUS_OK);

    /* the fixed part is copied bit for bit */
    fixed_vertices(labels, fixed);
    pleat_cwf_copy_amplitude(a, a0, nv);
    pleat_cwf_copy_amplitude(b, a1, nv);
    pleat_cwf_copy_zeta(a, z0, nv);
    pleat_cwf_copy_zeta(b, z1, nv);
    for (i = 0; i < nv; i++)
        if (fixed[i]) {
            n_fixed++;
            same &= memcmp(a0 + i, a1 + i, sizeof *a0) == 0;
            same &= memcmp(z0 + 2 * i, z1 + 2 * i, 2 * sizeof *z0) == 0;
        }
    CHECK(n_fixed > 0 && same);

    /* an identity edit returns the input */
    r.rotate_radians = 0.0;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, NULL, &c, NULL), PLEAT_STATUS_OK);
    pleat_cwf_copy_omega(a, w0, ne);
    pleat_cwf_copy_omega(c, w1, ne);
    same = 1;
    for (i = 0; i < ne; i++) same &= fabs(w0[i] - w1[i]) < 1e-12;
    CHECK(same);

    /* the edited keyframe evaluates like any other field */
    {
        PleatMesh *wrinkled = NULL;
        PleatWrinkleEvalParams p = pleat_wrinkle_eval_params_default();
        p.levels = 1;
        CHECK_STATUS(pleat_cwf_evaluate(b, &p, NULL, NULL, &wrinkled, NULL, NULL),
                     PLEAT_STATUS_OK);
        CHECK(pleat_mesh_triangle_count(wrinkled) == 4 * nt);
        pleat_mesh_destroy(wrinkled);
    }

    /* design from one source */
    src.vertex = centre;
    src.rings = 4;
    src.wave_vector[0] = k[0], src.wave_vector[1] = 0, src.wave_vector[2] = 0;
    src.amplitude = 0.02;
    CHECK_STATUS(pleat_cwf_design(m, &src, 1, NULL, NULL, &d), PLEAT_STATUS_OK);
    pleat_cwf_copy_amplitude(d, a1, nv);
    CHECK(a1[centre] == 0.02 && a1[0] == 0.0);

    /* with progress callbacks, cancelled */
    r.rotate_radians = M_PI / 2;
    progress_and_cancel(m, a, &r, &src, d, b, nv, nt);
    progress_misuse(m, a, &r, &src, nv, nt);

    /* misuse: a status and a message, nothing written */
    {
        PleatCwf *none = NULL;
        PleatCwfRegionEdit bad = r;
        PleatWrinkleSource nan_src = src;
        bad.frequency_scale = 0.0;
        CHECK_STATUS(pleat_cwf_edit(a, &bad, 1, NULL, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        bad = r;
        bad.struct_size = 4;
        CHECK_STATUS(pleat_cwf_edit(a, &bad, 1, NULL, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        bad = r;
        bad.faces = NULL;
        CHECK_STATUS(pleat_cwf_edit(a, &bad, 1, NULL, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        bad = r;
        bad.interface_rings = 0;
        CHECK_STATUS(pleat_cwf_edit(a, &bad, 1, NULL, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        {
            PleatCwfRegionEdit two[2];
            two[0] = r, two[1] = r;
            CHECK_STATUS(pleat_cwf_edit(a, two, 2, NULL, &none, NULL),
                         PLEAT_STATUS_INVALID_ARGUMENT);
        }
        CHECK_STATUS(pleat_cwf_edit(NULL, &r, 1, NULL, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_edit(a, &r, 1, NULL, NULL, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        ep.phase = 7;
        CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
        nan_src.wave_vector[1] = NAN;
        CHECK_STATUS(pleat_cwf_design(m, &nan_src, 1, NULL, NULL, &none),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_cwf_design(m, &src, 0, NULL, NULL, &none),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_mesh_grow_faces(m, NULL, 0, &centre, 1, 0, PLEAT_ADJACENCY_VERTEX,
                                           flags, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_mesh_grow_faces(m, NULL, 0, &centre, 1, 2, 9, flags, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK(none == NULL);
    }

    pleat_cwf_destroy(a);
    pleat_cwf_destroy(b);
    pleat_cwf_destroy(c);
    pleat_cwf_destroy(d);
    pleat_mesh_destroy(m);
    free(zeta), free(omega), free(amp), free(flags), free(labels), free(fixed), free(faces);
    free(a0), free(a1), free(z0), free(z1), free(w0), free(w1);
}

/* Checks `msg` names `field` (the status message of the last call). */
static void check_names(const char *field) {
    CHECK(strstr(pleat_last_error(), field) != NULL);
}

/* compat_target = 0.3: the interface is widened until the compatibility RMS is under 0.3 rad
   (or max_interface_rings is reached); the report says which widths and how many edits. */
static void adaptive_width(void) {
    const double k[3] = {2 * 2 * M_PI, 0, 0}; /* 2 waves: resolved on the 21^2 grid */
    PleatMesh *m = make_grid(N);
    size_t nv = pleat_mesh_vertex_count(m), nt = pleat_mesh_triangle_count(m), ne = 0, i, count = 0;
    double *zeta = (double *)malloc(2 * nv * sizeof *zeta);
    double *omega = plane_wave(m, k, &ne, zeta);
    double *amp = filled(nv, 0.01);
    uint8_t *flags = (uint8_t *)malloc(nt);
    uint32_t *faces = (uint32_t *)malloc(nt * sizeof *faces);
    uint32_t centre = (N / 2) * N + N / 2, rings[2] = {0, 0};
    PleatCwf *a = NULL, *fixed = NULL, *wide = NULL, *old = NULL, *none = NULL;
    PleatCwfRegionEdit r;
    PleatCwfEditParams ep = pleat_cwf_edit_params_default();
    PleatCwfEditReport narrow_rep, wide_rep, old_rep;

    CHECK(ep.edit_weight == 1.0 && ep.compat_target == 0.3 && ep.max_interface_rings == 8);
    CHECK_STATUS(pleat_cwf_create(m, omega, ne, amp, zeta, nv, &a), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_grow_faces(m, NULL, 0, &centre, 1, 3, PLEAT_ADJACENCY_VERTEX, flags,
                                       &count),
                 PLEAT_STATUS_OK);
    count = 0;
    for (i = 0; i < nt; i++)
        if (flags[i]) faces[count++] = (uint32_t)i;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    r.interface_rings = 1;
    r.faces = faces;
    r.face_count = count;
    r.rotate_radians = M_PI / 2;
    r.frequency_scale = 1.0;
    r.amplitude_scale = 1.0;

    /* the requested width (compat_target = 0: off) */
    ep.compat_target = 0.0;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &fixed, NULL), PLEAT_STATUS_OK);
    memset(&narrow_rep, 0, sizeof narrow_rep);
    narrow_rep.struct_size = sizeof narrow_rep;
    CHECK_STATUS(pleat_cwf_get_edit_report(fixed, &narrow_rep), PLEAT_STATUS_OK);
    CHECK(narrow_rep.attempts == 1 && narrow_rep.region_count == 1);
    CHECK(narrow_rep.interface_rings_min == 1 && narrow_rep.interface_rings_max == 1);

    /* adaptive: widened until the RMS is under 0.3 rad */
    ep.compat_target = 0.3;
    ep.max_interface_rings = 6;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &wide, NULL), PLEAT_STATUS_OK);
    memset(&wide_rep, 0, sizeof wide_rep);
    wide_rep.struct_size = sizeof wide_rep;
    CHECK_STATUS(pleat_cwf_get_edit_report(wide, &wide_rep), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_cwf_copy_edit_interface_rings(wide, rings, 2), PLEAT_STATUS_OK);
    printf("  compat_target 0.3: interface %u -> %u rings in %u edits; RMS %.3f -> %.3f rad "
           "(edit %.3f, interface %.3f, floor %.3f)\n",
           r.interface_rings, rings[0], wide_rep.attempts, narrow_rep.compat_rms,
           wide_rep.compat_rms, wide_rep.compat_rms_edit, wide_rep.compat_rms_interface,
           wide_rep.compat_floor);
    CHECK(narrow_rep.compat_rms > 0.3);
    CHECK(wide_rep.attempts > 1 && rings[0] > r.interface_rings);
    CHECK(rings[0] == wide_rep.interface_rings_max && wide_rep.region_count == 1);
    CHECK(wide_rep.compat_rms < narrow_rep.compat_rms);
    CHECK(wide_rep.compat_rms <= 0.3);
    CHECK_STATUS(pleat_cwf_copy_edit_interface_rings(wide, rings, 0), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_cwf_get_edit_report(a, &wide_rep), PLEAT_STATUS_INVALID_ARGUMENT);
    /* misuse: NULL handle or output */
    CHECK_STATUS(pleat_cwf_get_edit_report(NULL, &wide_rep), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_get_edit_report(wide, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_copy_edit_interface_rings(NULL, rings, 2), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_copy_edit_interface_rings(wide, NULL, 2), PLEAT_STATUS_INVALID_ARGUMENT);

    /* a caller compiled before the three fields: whatever follows its struct is ignored */
    {
        PleatCwfEditParams older = pleat_cwf_edit_params_default();
        older.struct_size = (uint32_t)offsetof(PleatCwfEditParams, edit_weight);
        older.edit_weight = NAN;
        older.compat_target = -1.0;
        older.max_interface_rings = 0;
        CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &older, &old, NULL), PLEAT_STATUS_OK);
        memset(&old_rep, 0, sizeof old_rep);
        /* an older report struct: only its prefix is written */
        old_rep.struct_size = (uint32_t)offsetof(PleatCwfEditReport, face_counts);
        old_rep.compat_rms = -7.0;
        CHECK_STATUS(pleat_cwf_get_edit_report(old, &old_rep), PLEAT_STATUS_OK);
        /* it gets the default adaptive width (0.3 rad), as `wide` with max_interface_rings 8 */
        CHECK(old_rep.attempts > 1 && old_rep.interface_rings_max > 1);
        CHECK(old_rep.compat_rms == -7.0);
        CHECK(old_rep.struct_size == offsetof(PleatCwfEditReport, face_counts));
    }

    /* animating the edit: locality (default 1) holds the unchanged vertices, 0 solves all; an
       older interpolation struct (before `locality`) keeps it on */
    {
        PleatWrinkleInterpParams ip = pleat_wrinkle_interp_params_default();
        PleatWrinkleInterpStats st;
        PleatCwfAnimation *anim = NULL;
        uint32_t locality;
        CHECK(ip.locality == 1);
        ip.guide_frames = 2, ip.substeps = 1, ip.max_iterations = 5;
        for (locality = 0; locality < 3; locality++) {
            memset(&st, 0, sizeof st);
            st.struct_size = sizeof st;
            ip.struct_size = sizeof ip;
            ip.locality = locality == 1;
            if (locality == 2) { /* the older struct: bytes after it are not read */
                ip.struct_size = (uint32_t)offsetof(PleatWrinkleInterpParams, locality);
                ip.locality = 0;
            }
            CHECK_STATUS(pleat_cwf_interpolate(a, wide, &ip, NULL, NULL, &anim, &st),
                         PLEAT_STATUS_OK);
            CHECK(locality == 0 ? st.pinned_vertices == 0 : st.pinned_vertices > 0);
            pleat_cwf_animation_destroy(anim);
            anim = NULL;
        }
        ip = pleat_wrinkle_interp_params_default();
        ip.locality = 2;
        CHECK_STATUS(pleat_cwf_interpolate(a, wide, &ip, NULL, NULL, &anim, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        check_names("locality");
        CHECK(anim == NULL);
    }

    /* NaN / negative compat_target, edit_weight < 1, max_interface_rings 0: refused, named */
    ep = pleat_cwf_edit_params_default();
    ep.compat_target = NAN;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    check_names("compat_target");
    ep.compat_target = -0.3;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    check_names("compat_target");
    ep = pleat_cwf_edit_params_default();
    ep.edit_weight = NAN;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    check_names("edit_weight");
    ep.edit_weight = -1.0;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    check_names("edit_weight");
    ep = pleat_cwf_edit_params_default();
    ep.max_interface_rings = 0;
    CHECK_STATUS(pleat_cwf_edit(a, &r, 1, &ep, &none, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    check_names("max_interface_rings");
    CHECK(none == NULL);

    pleat_cwf_destroy(a);
    pleat_cwf_destroy(fixed);
    pleat_cwf_destroy(wide);
    pleat_cwf_destroy(old);
    pleat_mesh_destroy(m);
    free(zeta), free(omega), free(amp), free(flags), free(faces);
}

/* Without the capability the calls answer UNSUPPORTED; the defaults still work. */
static void unsupported(void) {
    PleatMesh *m = make_grid(5);
    PleatCwf *out = NULL;
    uint8_t flags[32];
    uint32_t v = 12;
    PleatWrinkleSource s = {12, 2, {1, 0, 0}, 0.01};
    PleatCwfEditParams ep = pleat_cwf_edit_params_default();
    PleatCwfDesignParams dp = pleat_cwf_design_params_default();
    printf("SKIPPED: this pleat was built without \"wrinkle\"; checking UNSUPPORTED\n");
    CHECK(ep.struct_size == sizeof ep && dp.struct_size == sizeof dp);
    CHECK(ep.compat_target == 0.3 && ep.max_interface_rings == 8 && ep.edit_weight == 1.0);
    CHECK_STATUS(pleat_cwf_design(m, &s, 1, &dp, NULL, &out), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_edit(NULL, NULL, 0, &ep, &out, NULL), PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_mesh_grow_faces(m, NULL, 0, &v, 1, 2, PLEAT_ADJACENCY_VERTEX, flags, NULL),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK(out == NULL);
    pleat_mesh_destroy(m);
}

int main(void) {
    if (pleat_has_feature("wrinkle")) {
        edits();
        adaptive_width();
    } else
        unsupported();
    return finish("wrinkle_edit");
}
