/* Textured LODs from C: build a UV sphere with a procedural texture in C, bake a LOD at
 * n_p = 100, copy the baked mesh and images out, bake two materials (one per hemisphere) with
 * pleat_bake_lod_multi, transfer attributes with the provenance calls, cancel a bake from the
 * progress callback, and check that misuse gives an error status.
 */
#include <math.h>
#include <stddef.h>
#include "test_util.h"

#define SLICES 32
#define STACKS 16
#define NV ((SLICES + 1) * (STACKS + 1))
#define NT (2 * SLICES * STACKS)
#define TEX 64

/* A unit UV sphere: (SLICES+1) x (STACKS+1) vertices (the seam and poles duplicated, as UV
 * spheres are), per-vertex UVs u = longitude, v = latitude (v = 0 at the top). */
static void make_sphere(float *p, float *uv, uint32_t *t) {
    const double pi = 3.141592653589793;
    int i, j, k = 0;
    for (j = 0; j <= STACKS; j++) {
        for (i = 0; i <= SLICES; i++) {
            double u = (double)i / SLICES, v = (double)j / STACKS;
            double th = 2.0 * pi * u, ph = pi * v;
            int n = j * (SLICES + 1) + i;
            p[3 * n + 0] = (float)(sin(ph) * cos(th));
            p[3 * n + 1] = (float)(sin(ph) * sin(th));
            p[3 * n + 2] = (float)cos(ph);
            uv[2 * n + 0] = (float)u;
            uv[2 * n + 1] = (float)v;
        }
    }
    for (j = 0; j < STACKS; j++) {
        for (i = 0; i < SLICES; i++) {
            uint32_t a = (uint32_t)(j * (SLICES + 1) + i), b = a + 1;
            uint32_t c = a + SLICES + 1, d = c + 1;
            t[k++] = a; t[k++] = c; t[k++] = d;
            t[k++] = a; t[k++] = d; t[k++] = b;
        }
    }
}

/* An sRGB checker (8 x 8 squares) over a red-to-blue gradient. */
static void make_texture(uint8_t *rgba) {
    int x, y;
    for (y = 0; y < TEX; y++) {
        for (x = 0; x < TEX; x++) {
            int on = ((x / 8) + (y / 8)) % 2;
            uint8_t *px = rgba + 4 * (y * TEX + x);
            px[0] = (uint8_t)(255 * x / (TEX - 1));
            px[1] = on ? 200 : 40;
            px[2] = (uint8_t)(255 - 255 * y / (TEX - 1));
            px[3] = 255;
        }
    }
}

typedef struct {
    int calls;
    int cancel_at_texels; /* 1: answer "stop" at the first texel report */
} Progress;

static int on_progress(void *user_data, const PleatProgress *info) {
    Progress *p = (Progress *)user_data;
    p->calls++;
    CHECK(info->fraction >= 0.0 && info->fraction <= 1.0);
    if (p->cancel_at_texels && strcmp(info->stage, "bake: texels") == 0) return 1;
    return 0;
}

static PleatBakeMaterial textured(const float *uv, const uint8_t *tex) {
    PleatBakeMaterial m = pleat_bake_material_default();
    m.uvs = uv;
    m.uv_count = NV;
    m.base_color.rgba = tex;
    m.base_color.width = TEX;
    m.base_color.height = TEX;
    m.base_color.srgb = 1;
    m.metallic_factor = 0.0;
    return m;
}

static PleatBakeParams bake_params(void) {
    PleatBakeParams bp = pleat_bake_params_default();
    bp.screen_size = 100.0;
    bp.texture_size = 64; /* small: the program also runs under valgrind */
    bp.error_samples = 500;
    return bp;
}

static void check_bake(const PleatBake *bake, const PleatMesh *lod) {
    size_t nv = pleat_bake_vertex_count(bake), nt = pleat_bake_triangle_count(bake), i;
    float *uv = (float *)malloc(2 * nv * sizeof(float));
    float *tg = (float *)malloc(4 * nv * sizeof(float));
    double *pos = (double *)malloc(3 * nv * sizeof(double));
    uint32_t *idx = (uint32_t *)malloc(3 * nt * sizeof(uint32_t));
    uint32_t w = 0, h = 0;
    PleatBakeStats st;
    CHECK(nv >= pleat_mesh_vertex_count(lod));
    CHECK(nt == pleat_mesh_triangle_count(lod));
    CHECK_STATUS(pleat_bake_copy_uvs(bake, uv, nv), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_bake_copy_tangents(bake, tg, nv), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_bake_copy_positions(bake, pos, nv), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_bake_copy_indices(bake, idx, 3 * nt), PLEAT_STATUS_OK);
    for (i = 0; i < 2 * nv; i++) CHECK(uv[i] >= 0.0f && uv[i] <= 1.0f);
    for (i = 0; i < 3 * nt; i++) CHECK(idx[i] < nv);
    for (i = 0; i < nv; i++) CHECK(tg[4 * i + 3] == 1.0f || tg[4 * i + 3] == -1.0f);
    /* Short capacities and absent attributes are errors, not crashes. */
    CHECK_STATUS(pleat_bake_copy_uvs(bake, uv, nv - 1), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_bake_copy_indices(bake, idx, 3 * nt - 1), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_bake_copy_uvs(bake, NULL, nv), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_bake_copy_colors(bake, tg, nv), PLEAT_STATUS_INVALID_ARGUMENT);

    CHECK_STATUS(pleat_bake_image_size(bake, PLEAT_BAKE_IMAGE_BASE_COLOR, &w, &h),
                 PLEAT_STATUS_OK);
    CHECK(w == 64 && h == 64);
    if (w == 64 && h == 64) {
        uint8_t *img = (uint8_t *)malloc(4 * (size_t)w * h);
        int seen_dark = 0, seen_bright = 0;
        CHECK_STATUS(pleat_bake_copy_image(bake, PLEAT_BAKE_IMAGE_BASE_COLOR, img, 4 * w * h),
                     PLEAT_STATUS_OK);
        for (i = 0; i < (size_t)w * h; i++) {
            if (img[4 * i + 1] < 90) seen_dark = 1;   /* a dark checker square */
            if (img[4 * i + 1] > 160) seen_bright = 1; /* a bright one */
        }
        CHECK(seen_dark && seen_bright);
        CHECK_STATUS(pleat_bake_copy_image(bake, PLEAT_BAKE_IMAGE_BASE_COLOR, img, 100),
                     PLEAT_STATUS_LIMIT_EXCEEDED);
        CHECK_STATUS(pleat_bake_copy_image(bake, 99, img, 4 * w * h),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(pleat_bake_copy_image(bake, PLEAT_BAKE_IMAGE_OCCLUSION, img, 4 * w * h),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        free(img);
    }
    CHECK_STATUS(pleat_bake_image_size(bake, PLEAT_BAKE_IMAGE_NORMAL, &w, &h), PLEAT_STATUS_OK);
    CHECK(w == 64 && h == 64);
    memset(&st, 0, sizeof st);
    st.struct_size = sizeof st;
    CHECK_STATUS(pleat_bake_get_stats(bake, &st), PLEAT_STATUS_OK);
    CHECK(st.flags & PLEAT_BAKE_TEXTURED);
    CHECK(st.texture_size == 64 && st.charts > 0 && st.texels_covered > 0);
    CHECK(st.vertex_count == nv && st.triangle_count == nt);
    CHECK(st.atlas_padding > 0 && st.seam_clean_mip >= 0);
    printf("bake: %zu vertices, %zu triangles, %u charts, %llu texels covered, error mean %.2f "
           "/255, %.3f s, padding %u texels, seams clean to mip %d\n",
           nv, nt, st.charts, (unsigned long long)st.texels_covered, st.appearance_error_mean,
           st.seconds_total, st.atlas_padding, st.seam_clean_mip);
    {
        /* An older, shorter PleatBakeStats (before atlas_padding) is still accepted and
         * filled only up to its size. */
        PleatBakeStats old;
        memset(&old, 0xAB, sizeof old);
        old.struct_size = (uint32_t)offsetof(PleatBakeStats, atlas_padding);
        CHECK_STATUS(pleat_bake_get_stats(bake, &old), PLEAT_STATUS_OK);
        CHECK(old.charts == st.charts && old.atlas_padding == 0xABABABABu);
    }
    free(uv);
    free(tg);
    free(pos);
    free(idx);
}

static void check_provenance(const PleatMesh *lod, const PleatMesh *input) {
    size_t n = pleat_mesh_vertex_count(lod), i;
    uint32_t *tri = (uint32_t *)malloc(n * sizeof(uint32_t));
    double *bary = (double *)malloc(3 * n * sizeof(double));
    uint8_t *flags = (uint8_t *)malloc(n);
    PleatProvenanceParams pp = pleat_provenance_params_default();
    const double top[3] = {0.0, 0.0, 1.2}, up[3] = {0.0, 0.0, 1.0};
    uint32_t t1;
    double b1[3];
    uint8_t f1 = 0;
    pp.screen_size = 100.0;
    CHECK_STATUS(pleat_lod_provenance(lod, input, &pp, tri, n, bary, 3 * n, flags, n),
                 PLEAT_STATUS_OK);
    for (i = 0; i < n; i++) {
        double s = bary[3 * i] + bary[3 * i + 1] + bary[3 * i + 2];
        CHECK(tri[i] < NT);
        CHECK(fabs(s - 1.0) < 1e-9);
        CHECK(bary[3 * i] >= 0.0 && bary[3 * i + 1] >= 0.0 && bary[3 * i + 2] >= 0.0);
    }
    /* An engine's own point above the north pole casts down onto the top cap. */
    pp.envelope = 0.5;
    CHECK_STATUS(pleat_points_provenance(input, top, up, 1, &pp, &t1, 1, b1, 3, &f1, 1),
                 PLEAT_STATUS_OK);
    CHECK(f1 == PLEAT_PROVENANCE_BY_RAY);
    CHECK(t1 < 2 * SLICES); /* the first stack */
    /* Misuse. */
    CHECK_STATUS(pleat_lod_provenance(lod, input, &pp, tri, n - 1, bary, 3 * n, NULL, 0),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_lod_provenance(lod, input, &pp, tri, n, NULL, 3 * n, NULL, 0),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_provenance(NULL, input, &pp, tri, n, bary, 3 * n, NULL, 0),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_provenance(lod, input, &pp, tri, n, bary, 3 * n, flags, 1),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    pp.screen_size = NAN;
    CHECK_STATUS(pleat_lod_provenance(lod, input, &pp, tri, n, bary, 3 * n, NULL, 0),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    pp = pleat_provenance_params_default();
    {
        const double bad[3] = {0.0, NAN, 1.0};
        CHECK_STATUS(pleat_points_provenance(input, bad, NULL, 1, &pp, &t1, 1, b1, 3, NULL, 0),
                     PLEAT_STATUS_INVALID_ARGUMENT);
    }
    free(tri);
    free(bary);
    free(flags);
}

static void check_misuse(const PleatMesh *lod, const PleatMesh *input, const float *uv,
                         const uint8_t *tex) {
    PleatBakeMaterial m = textured(uv, tex);
    PleatBakeParams bp = bake_params();
    PleatBake *bake = NULL;
    float *bad_uv = (float *)malloc(2 * NV * sizeof(float));
    memcpy(bad_uv, uv, 2 * NV * sizeof(float));
    bad_uv[17] = NAN;

    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_bake_lod(lod, input, NULL, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_bake_lod(NULL, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m.uvs = bad_uv;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m.uvs = uv;
    m.uv_count = NV - 1;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m.uv_count = NV;
    m.uvs = NULL;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    m.base_color.width = 100000; /* over the pixel budget: rejected before it is read */
    m.base_color.height = 100000;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    m = textured(uv, tex);
    m.base_color.width = 0;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    m.base_color.rgba = NULL;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    m.base_color.srgb = 7;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    m.wrap = 9;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    m.struct_size = 4;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    m = textured(uv, tex);
    bp.screen_size = -1.0;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    bp = bake_params();
    bp.texture_size = 100000;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    bp = bake_params();
    bp.threads = 1000;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(bake == NULL); /* nothing written on failure */
    /* NULL handles to the getters. */
    CHECK(pleat_bake_vertex_count(NULL) == 0);
    CHECK_STATUS(pleat_bake_copy_uvs(NULL, bad_uv, NV), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_bake_write_glb(NULL, "x.glb"), PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_bake_free(NULL);
    free(bad_uv);
}

/* Whether two 64 x 64 bakes hold the same bytes in image `which`. */
static int same_image(const PleatBake *x, const PleatBake *y, uint32_t which) {
    uint8_t *a = (uint8_t *)malloc(4 * 64 * 64), *b = (uint8_t *)malloc(4 * 64 * 64);
    int same;
    CHECK_STATUS(pleat_bake_copy_image(x, which, a, 4 * 64 * 64), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_bake_copy_image(y, which, b, 4 * 64 * 64), PLEAT_STATUS_OK);
    same = memcmp(a, b, 4 * 64 * 64) == 0;
    free(a);
    free(b);
    return same;
}

/* Two materials: the checker on the upper hemisphere (the first STACKS/2 rows of triangles),
 * an untextured pure green on the lower one; then the 1-material case of the same call gives
 * pleat_bake_lod's bytes; then misuse of the material array and the per-triangle indices. */
static void check_multi(const PleatMesh *lod, const PleatMesh *input, const float *uv,
                        const uint8_t *tex, const PleatBake *single) {
    PleatBakeMaterial ms[2];
    PleatBakeParams bp = bake_params();
    PleatBake *bake = NULL, *one = NULL, *bad = NULL;
    uint32_t *tm = (uint32_t *)malloc(NT * sizeof(uint32_t));
    size_t i;
    ms[0] = textured(uv, tex);
    ms[1] = pleat_bake_material_default();
    ms[1].base_color_factor[0] = 0.0;
    ms[1].base_color_factor[2] = 0.0;
    for (i = 0; i < NT; i++) tm[i] = i < NT / 2 ? 0 : 1;
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 2, tm, NT, &bp, NULL, NULL, &bake, NULL),
                 PLEAT_STATUS_OK);
    if (bake) {
        uint8_t *img = (uint8_t *)malloc(4 * 64 * 64);
        int green = 0, checker = 0;
        CHECK_STATUS(pleat_bake_copy_image(bake, PLEAT_BAKE_IMAGE_BASE_COLOR, img, 4 * 64 * 64),
                     PLEAT_STATUS_OK);
        for (i = 0; i < 64 * 64; i++) {
            const uint8_t *px = img + 4 * i;
            if (px[0] < 20 && px[1] > 240 && px[2] < 20) green++;
            if (px[1] > 160 && px[1] < 230) checker++;
        }
        CHECK(green > 200 && checker > 100);
        printf("bake_multi: %d green texels, %d bright checker texels\n", green, checker);
        free(img);
    }
    /* One material, no per-triangle array: the bytes of pleat_bake_lod. */
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 1, NULL, 0, &bp, NULL, NULL, &one, NULL),
                 PLEAT_STATUS_OK);
    if (one && single) CHECK(same_image(one, single, PLEAT_BAKE_IMAGE_BASE_COLOR));
    /* Misuse: each an error status, nothing written. */
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, NULL, 2, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 0, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(
        pleat_bake_lod_multi(lod, input, ms, 2, tm, NT - 1, &bp, NULL, NULL, &bad, NULL),
        PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(
        pleat_bake_lod_multi(lod, input, ms, 2, NULL, NT, &bp, NULL, NULL, &bad, NULL),
        PLEAT_STATUS_INVALID_ARGUMENT);
    tm[NT - 1] = 2; /* out of range */
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 2, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(pleat_last_error(), "triangle_material") != NULL);
    tm[NT - 1] = 1;
    ms[1].uvs = uv; /* the mesh arrays come from materials[0] only */
    ms[1].uv_count = NV;
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 2, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    ms[1].uvs = NULL;
    ms[1].uv_count = 0;
    ms[1].struct_size = 8; /* every element needs the same struct_size */
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 2, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    ms[1] = pleat_bake_material_default();
    ms[1].base_color.width = 4; /* an image without pixels */
    ms[1].base_color.height = 4;
    CHECK_STATUS(pleat_bake_lod_multi(lod, input, ms, 2, tm, NT, &bp, NULL, NULL, &bad, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(pleat_last_error(), "materials[1]") != NULL);
    CHECK(bad == NULL);
    pleat_bake_free(bake);
    pleat_bake_free(one);
    free(tm);
}

int main(void) {
    float *pos = (float *)malloc(3 * NV * sizeof(float));
    float *uv = (float *)malloc(2 * NV * sizeof(float));
    uint32_t *tri = (uint32_t *)malloc(3 * NT * sizeof(uint32_t));
    uint8_t *tex = (uint8_t *)malloc(4 * TEX * TEX);
    PleatMesh *input = NULL, *lod = NULL;
    PleatLodParams lp = pleat_lod_params_default();
    PleatBakeMaterial m;
    PleatBakeParams bp = bake_params();
    PleatBake *bake = NULL, *bake2 = NULL, *cancelled = NULL, *plain = NULL;
    Progress prog = {0, 0};

    if (!pleat_has_feature("bake")) {
        printf("bake_lod: SKIPPED (this build has no `bake` capability)\n");
        PleatBake *b = NULL;
        CHECK_STATUS(pleat_bake_lod(NULL, NULL, NULL, NULL, NULL, NULL, &b, NULL),
                     PLEAT_STATUS_UNSUPPORTED);
        return finish("bake_lod");
    }
    make_sphere(pos, uv, tri);
    make_texture(tex);
    CHECK_STATUS(pleat_mesh_create_f32(pos, NV, 0, tri, 3 * NT, &input), PLEAT_STATUS_OK);
    lp.screen_size = 100.0;
    lp.max_rounds = 4; /* light: the program also runs under valgrind */
    CHECK_STATUS(pleat_lod_generate(input, &lp, NULL, NULL, &lod, NULL), PLEAT_STATUS_OK);
    if (!input || !lod) return finish("bake_lod");
    printf("LOD n_p=100: %zu vertices, %zu triangles\n", pleat_mesh_vertex_count(lod),
           pleat_mesh_triangle_count(lod));

    m = textured(uv, tex);
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, on_progress, &prog, &bake, NULL),
                 PLEAT_STATUS_OK);
    CHECK(prog.calls > 0);
    if (bake) {
        check_bake(bake, lod);
        CHECK_STATUS(pleat_bake_write_glb(bake, "target/bake_lod_example.glb"), PLEAT_STATUS_OK);
        remove("target/bake_lod_example.glb");
    }

    /* Two workers of its own: the same bytes. */
    bp.threads = 2;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, on_progress, &prog, &bake2, NULL),
                 PLEAT_STATUS_OK);
    if (bake && bake2) CHECK(same_image(bake, bake2, PLEAT_BAKE_IMAGE_NORMAL));
    bp.threads = 0;

    /* Cancel from the callback at the texel stage. */
    prog.cancel_at_texels = 1;
    CHECK_STATUS(pleat_bake_lod(lod, input, &m, &bp, on_progress, &prog, &cancelled, NULL),
                 PLEAT_STATUS_CANCELLED);
    CHECK(cancelled == NULL);

    /* No image: vertex colours (the sphere's z as a colour), no UVs. */
    {
        float *col = (float *)malloc(4 * NV * sizeof(float));
        size_t i, nv;
        PleatBakeMaterial vm = pleat_bake_material_default();
        for (i = 0; i < NV; i++) {
            col[4 * i + 0] = 0.5f + 0.5f * pos[3 * i + 2];
            col[4 * i + 1] = 0.2f;
            col[4 * i + 2] = 0.5f - 0.5f * pos[3 * i + 2];
            col[4 * i + 3] = 1.0f;
        }
        vm.colors = col;
        CHECK_STATUS(pleat_bake_lod(lod, input, &vm, &bp, NULL, NULL, &plain, NULL),
                     PLEAT_STATUS_OK);
        if (plain) {
            float *out;
            nv = pleat_bake_vertex_count(plain);
            out = (float *)malloc(4 * nv * sizeof(float));
            CHECK(nv == pleat_mesh_vertex_count(lod));
            CHECK_STATUS(pleat_bake_copy_colors(plain, out, nv), PLEAT_STATUS_OK);
            for (i = 0; i < 4 * nv; i++) CHECK(out[i] >= -1e-6f && out[i] <= 1.0f + 1e-6f);
            CHECK_STATUS(pleat_bake_copy_uvs(plain, out, nv), PLEAT_STATUS_INVALID_ARGUMENT);
            free(out);
        }
        free(col);
    }

    check_multi(lod, input, uv, tex, bake);
    check_provenance(lod, input);
    check_misuse(lod, input, uv, tex);

    pleat_bake_free(bake);
    pleat_bake_free(bake2);
    pleat_bake_free(plain);
    pleat_mesh_destroy(lod);
    pleat_mesh_destroy(input);
    free(pos);
    free(uv);
    free(tri);
    free(tex);
    return finish("bake_lod");
}
