/* Wrinkle animation from C (dissertation §3.4): the rigid-rotation test of Fig. 3.8 on a tiny
   grid, save/load of the animation, and every documented misuse of the new calls (status +
   message, no output, no abort). Kept tiny: it runs under valgrind in CI. */
#include "wrinkle_util.h"

#define N 9 /* 9x9 grid on [0,1]^2 */
#define K 8.0

static PleatCwf *wave(PleatMesh *g, double kx, double ky) {
    double k[3];
    size_t ne, nv = pleat_mesh_vertex_count(g);
    double *zeta = filled(2 * nv, 0), *amp = filled(nv, 0.01), *w;
    PleatCwf *c = NULL;
    k[0] = kx, k[1] = ky, k[2] = 0;
    w = plane_wave(g, k, &ne, zeta);
    CHECK_STATUS(pleat_cwf_create(g, w, ne, amp, zeta, nv, &c), PLEAT_STATUS_OK);
    free(zeta);
    free(amp);
    free(w);
    return c;
}

static int cancel_at_second(void *user_data, const PleatProgress *info) {
    int *calls = (int *)user_data;
    (void)info;
    return ++*calls >= 2;
}

/* Largest |wrap(arg z_l - arg z_k - omega_kl)| over edges: 0 for an exactly compatible field. */
static double max_incompatibility(const PleatMesh *g, const PleatCwf *c) {
    size_t ne, nv = pleat_cwf_vertex_count(c), i;
    uint32_t *e = edges_of(g, &ne);
    double *w = filled(ne, 0), *z = filled(2 * nv, 0), worst = 0;
    pleat_cwf_copy_omega(c, w, ne);
    pleat_cwf_copy_zeta(c, z, nv);
    for (i = 0; i < ne; i++) {
        const double *a = z + 2 * e[2 * i], *b = z + 2 * e[2 * i + 1];
        double d = wrap_pi(atan2(b[1], b[0]) - atan2(a[1], a[0]) - w[i]);
        if (fabs(d) > worst) worst = fabs(d);
    }
    free(e);
    free(w);
    free(z);
    return worst;
}

static void rotation(void) {
    PleatMesh *g = make_grid(N);
    PleatCwf *a = wave(g, K, 0), *b = wave(g, 0, K), *mid = NULL, *end = NULL;
    PleatWrinkleInterpParams p = pleat_wrinkle_interp_params_default();
    PleatWrinkleInterpStats st;
    PleatCwfAnimation *anim = NULL, *back = NULL;
    size_t nv = pleat_mesh_vertex_count(g), ne, i, nh;
    double *w = NULL, *z = NULL, *zb = NULL, kt[3], min_abs = 1e9, worst = 0, *hist;
    uint32_t *e;
    double *x = positions_of(g);
    p.guide_frames = 10;
    p.substeps = 2;
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, &st), PLEAT_STATUS_OK);
    CHECK(st.stop_reason == PLEAT_INTERP_STOP_CONVERGED && st.iterations > 0);
    CHECK(st.final_gradient_norm <= 1e-6 && st.g_ave > 0 && st.c > 0);
    CHECK(pleat_cwf_animation_frame_count(anim) == 21);
    CHECK(pleat_cwf_animation_guide_count(anim) == 10);
    nh = pleat_cwf_animation_history_count(anim);
    CHECK(nh == (size_t)st.iterations + 1);
    hist = filled(2 * nh, -1);
    CHECK_STATUS(pleat_cwf_animation_copy_history(anim, hist, nh), PLEAT_STATUS_OK);
    CHECK(hist[0] >= 0 && hist[2 * nh - 1] <= 1e-6);
    free(hist);

    /* t = 1 is keyframe b exactly */
    CHECK_STATUS(pleat_cwf_animation_frame(anim, 1.0, &end), PLEAT_STATUS_OK);
    z = filled(2 * nv, 0);
    zb = filled(2 * nv, 0);
    pleat_cwf_copy_zeta(end, z, nv);
    pleat_cwf_copy_zeta(b, zb, nv);
    CHECK(memcmp(z, zb, 2 * nv * sizeof *z) == 0);

    /* t = 0.5: omega is the plane wave turned by 45 degrees, z~ is compatible with it and has
       no singular line (linear interpolation would vanish along x - y = odd pi / K) */
    CHECK_STATUS(pleat_cwf_animation_frame(anim, 0.5, &mid), PLEAT_STATUS_OK);
    e = edges_of(g, &ne);
    w = filled(ne, 0);
    pleat_cwf_copy_omega(mid, w, ne);
    kt[0] = K * cos(M_PI / 4), kt[1] = K * sin(M_PI / 4), kt[2] = 0;
    for (i = 0; i < ne; i++) {
        const double *pa = x + 3 * e[2 * i], *pb = x + 3 * e[2 * i + 1];
        double d[3], err;
        d[0] = pb[0] - pa[0], d[1] = pb[1] - pa[1], d[2] = 0;
        err = fabs(w[i] - dot3(kt, d));
        if (err > worst) worst = err;
    }
    pleat_cwf_copy_zeta(mid, z, nv);
    for (i = 0; i < nv; i++) {
        double r = hypot(z[2 * i], z[2 * i + 1]);
        if (r < min_abs) min_abs = r;
    }
    printf("wrinkle_interp: rotation t=0.5: |omega - rotated wave| %.2e, min |z~| %.3f, "
           "max incompatibility %.3f rad, %u iterations\n",
           worst, min_abs, max_incompatibility(g, mid), st.iterations);
    CHECK(worst < 1e-9);
    CHECK(min_abs > 0.8);
    CHECK(max_incompatibility(g, mid) < 0.3);

    /* save / load reproduces the frames bit for bit */
    CHECK_STATUS(pleat_cwf_animation_write_file(anim, "target/wrinkle_interp_test.cwfa"),
                 PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_cwf_animation_read_file(g, "target/wrinkle_interp_test.cwfa", &back),
                 PLEAT_STATUS_OK);
    CHECK(pleat_cwf_animation_history_count(back) == 0);
    pleat_cwf_destroy(end);
    end = NULL;
    CHECK_STATUS(pleat_cwf_animation_frame(back, 0.5, &end), PLEAT_STATUS_OK);
    pleat_cwf_copy_zeta(end, zb, nv);
    CHECK(memcmp(z, zb, 2 * nv * sizeof *z) == 0);
    remove("target/wrinkle_interp_test.cwfa");

    free(e);
    free(w);
    free(z);
    free(zb);
    free(x);
    pleat_cwf_destroy(mid);
    pleat_cwf_destroy(end);
    pleat_cwf_animation_destroy(anim);
    pleat_cwf_animation_destroy(back);
    pleat_cwf_destroy(a);
    pleat_cwf_destroy(b);
    pleat_mesh_destroy(g);
}

static void misuse(void) {
    PleatMesh *g = make_grid(5), *g2 = make_grid(6);
    PleatCwf *a = wave(g, 3, 0), *b = wave(g, 0, 3), *other = wave(g2, 0, 3), *f = NULL;
    PleatCwfAnimation *anim = NULL;
    PleatWrinkleInterpParams p = pleat_wrinkle_interp_params_default();
    PleatWrinkleInterpStats st;
    double h[2];
    int calls = 0;
    p.guide_frames = 4;
    CHECK_STATUS(pleat_cwf_interpolate(NULL, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_interpolate(a, NULL, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_interpolate(a, other, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT); /* different base meshes */
    CHECK(strstr(pleat_last_error(), "different base meshes") != NULL);
    p.guide_frames = 0;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.guide_frames = 4;
    p.c_scale = NAN;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.c_scale = 1e3;
    p.gradient_tolerance = -1;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.gradient_tolerance = 1e-6;
    p.hessian = 99;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.hessian = PLEAT_INTERP_HESSIAN_TRUST_REGION;
    p.struct_size = 4;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.struct_size = sizeof p;
    st.struct_size = 2;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, NULL, NULL, &anim, &st),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.gradient_tolerance = 0; /* never converges: the callback cancels at its 2nd report */
    CHECK_STATUS(pleat_cwf_interpolate(a, b, &p, cancel_at_second, &calls, &anim, NULL),
                 PLEAT_STATUS_CANCELLED);
    CHECK(anim == NULL && calls == 2);
    p.gradient_tolerance = 1e-6;
    CHECK_STATUS(pleat_cwf_interpolate(a, b, NULL, NULL, NULL, &anim, NULL), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_cwf_animation_frame(anim, 1.5, &f), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_frame(anim, NAN, &f), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_frame(anim, -0.1, &f), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_frame(NULL, 0.5, &f), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_frame(anim, 0.5, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(f == NULL);
    CHECK_STATUS(pleat_cwf_animation_copy_history(anim, h, 0), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_cwf_animation_copy_history(anim, NULL, 10),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_write_file(anim, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_write_file(NULL, "x.cwfa"), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_write_file(anim, "/nonexistent-dir/x.cwfa"),
                 PLEAT_STATUS_IO);
    CHECK_STATUS(pleat_cwf_animation_write_file(anim, "target/wrinkle_interp_misuse.cwfa"),
                 PLEAT_STATUS_OK);
    pleat_cwf_animation_destroy(anim);
    anim = NULL;
    CHECK_STATUS(pleat_cwf_animation_read_file(g2, "target/wrinkle_interp_misuse.cwfa", &anim),
                 PLEAT_STATUS_INVALID_ARGUMENT); /* written for another base mesh */
    CHECK_STATUS(pleat_cwf_animation_read_file(g, "target/no-such-file.cwfa", &anim),
                 PLEAT_STATUS_IO);
    CHECK_STATUS(pleat_cwf_animation_read_file(g, "examples_c/wrinkle_interp.c", &anim),
                 PLEAT_STATUS_PARSE);
    CHECK_STATUS(pleat_cwf_animation_read_file(NULL, "x", &anim), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_cwf_animation_read_file(g, "target/wrinkle_interp_misuse.cwfa", NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(anim == NULL);
    remove("target/wrinkle_interp_misuse.cwfa");
    CHECK(pleat_cwf_animation_frame_count(NULL) == 0);
    pleat_cwf_animation_destroy(NULL);
    pleat_cwf_destroy(a);
    pleat_cwf_destroy(b);
    pleat_cwf_destroy(other);
    pleat_mesh_destroy(g);
    pleat_mesh_destroy(g2);
}

static void unsupported(void) {
    PleatCwfAnimation *anim = NULL;
    PleatCwf *f = NULL;
    CHECK_STATUS(pleat_cwf_interpolate(NULL, NULL, NULL, NULL, NULL, &anim, NULL),
                 PLEAT_STATUS_UNSUPPORTED);
    CHECK_STATUS(pleat_cwf_animation_frame(NULL, 0.5, &f), PLEAT_STATUS_UNSUPPORTED);
    CHECK(anim == NULL && f == NULL && pleat_cwf_animation_frame_count(NULL) == 0);
    CHECK(pleat_wrinkle_interp_params_default().guide_frames == 50);
}

int main(void) {
    if (pleat_has_feature("wrinkle")) {
        rotation();
        misuse();
    } else {
        unsupported();
    }
    return finish("wrinkle_interp");
}
