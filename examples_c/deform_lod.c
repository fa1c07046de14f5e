/* LODs that bend with their skin: a tube on two joints, simplified with and without its
 * deformation (pleat_deformation_create + PleatLodParams::deformation), weights carried onto
 * each level (pleat_transfer_skin), then both posed with joint 1 turned 1 rad by linear blend
 * skinning evaluated here. The level that followed the skin stays near the posed tube; the
 * plain one cuts the bend. Then the misuse cases. */
#include <math.h>
#include "test_util.h"

#define SEG 16
#define RINGS 25
#define NV (SEG * RINGS + 2)
#define NT (2 * SEG * (RINGS - 1) + 2 * SEG)
#define ANGLE 1.0

static double pos[3 * NV];
static uint32_t tri[3 * NT], joints[2 * NV];
static float weights[2 * NV];

/* The tube: radius 0.3 from y = 0 to 2, capped; joint 1 (pivot (0,1,0)) takes over from
 * joint 0 across y in [0.8, 1.2]. */
static void tube(void) {
    int r, s, k = 0;
    for (r = 0; r < RINGS; r++)
        for (s = 0; s < SEG; s++) {
            int v = r * SEG + s;
            double a = 6.283185307179586 * s / SEG;
            pos[3 * v] = 0.3 * cos(a), pos[3 * v + 1] = 2.0 * r / (RINGS - 1);
            pos[3 * v + 2] = 0.3 * sin(a);
            if (r + 1 < RINGS) {
                uint32_t a0 = (uint32_t)v, a1 = (uint32_t)(r * SEG + (s + 1) % SEG);
                tri[k++] = a0, tri[k++] = a1 + SEG, tri[k++] = a1;
                tri[k++] = a0, tri[k++] = a0 + SEG, tri[k++] = a1 + SEG;
            }
        }
    pos[3 * (NV - 2) + 1] = 0.0, pos[3 * (NV - 1) + 1] = 2.0;
    for (s = 0; s < SEG; s++) {
        tri[k++] = NV - 2, tri[k++] = (uint32_t)s, tri[k++] = (uint32_t)((s + 1) % SEG);
        tri[k++] = NV - 1, tri[k++] = (uint32_t)((RINGS - 1) * SEG + (s + 1) % SEG);
        tri[k++] = (uint32_t)((RINGS - 1) * SEG + s);
    }
    for (r = 0; r < NV; r++) {
        double t = (pos[3 * r + 1] - 0.8) / 0.4;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        joints[2 * r] = 0, joints[2 * r + 1] = 1;
        weights[2 * r] = (float)(1 - t), weights[2 * r + 1] = (float)t;
    }
}

/* Linear blend skinning: joint 0 rests, joint 1 turns by ANGLE about z through (0,1,0). */
static void pose(const double *p, const uint32_t *j, const float *w, int k, double *out) {
    double c = cos(ANGLE), s = sin(ANGLE), x = p[0], y = p[1] - 1.0;
    double turned[3] = {c * x - s * y, s * x + c * y + 1.0, p[2]};
    int i, a;
    out[0] = out[1] = out[2] = 0;
    for (i = 0; i < k; i++)
        for (a = 0; a < 3; a++) out[a] += w[i] * (j[i] == 1 ? turned[a] : p[a]);
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Distance from p to triangle abc (closest point by Voronoi regions, Ericson 5.1.5). */
static double point_triangle(const double *p, const double *a, const double *b, const double *c) {
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], d1, d2, d3, d4, d5, d6, va, vb, vc, v, w;
    int i;
    for (i = 0; i < 3; i++) ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
    d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    for (i = 0; i < 3; i++) bp[i] = p[i] - b[i], cp[i] = p[i] - c[i];
    d3 = dot3(ab, bp), d4 = dot3(ac, bp), d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0 && d2 <= 0) v = 0, w = 0;
    else if (d3 >= 0 && d4 <= d3) v = 1, w = 0;
    else if (d6 >= 0 && d5 <= d6) v = 0, w = 1;
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) v = d1 / (d1 - d3), w = 0;
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) v = 0, w = d2 / (d2 - d6);
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6)), v = 1 - w;
    else v = vb / (va + vb + vc), w = vc / (va + vb + vc);
    for (i = 0; i < 3; i++) q[i] = p[i] - (a[i] + v * ab[i] + w * ac[i]);
    return sqrt(dot3(q, q));
}

/* The largest distance from the posed level (its triangles' centroids and edge midpoints,
 * between skinned corners as a GPU draws them) to the posed input; -1 on failure. */
static double posed_error(PleatMesh *input, PleatMesh *lod, double n_p) {
    static double posed_in[3 * NV];
    PleatTransfer *tr = NULL;
    PleatTransferParams tp = pleat_transfer_params_default();
    size_t n = pleat_mesh_vertex_count(lod), m = pleat_mesh_triangle_count(lod), i, t;
    double *lp = malloc(3 * n * sizeof *lp), *posed = malloc(3 * n * sizeof *posed), worst = 0;
    uint32_t *lt = malloc(3 * m * sizeof *lt), *lj = malloc(4 * n * sizeof *lj);
    float *lw = malloc(4 * n * sizeof *lw);
    static const double bary[4][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
    tp.screen_size = n_p;
    if (!lp || !posed || !lt || !lj || !lw ||
        pleat_mesh_copy_positions_f64(lod, lp, n, 0) != PLEAT_STATUS_OK ||
        pleat_mesh_copy_indices(lod, lt, 3 * m) != PLEAT_STATUS_OK ||
        pleat_transfer_create(input, lod, &tp, &tr) != PLEAT_STATUS_OK ||
        pleat_transfer_skin(tr, joints, weights, NV, 2, 4, lj, lw, n) != PLEAT_STATUS_OK) {
        worst = -1;
        goto done;
    }
    for (i = 0; i < NV; i++) pose(pos + 3 * i, joints + 2 * i, weights + 2 * i, 2, posed_in + 3 * i);
    for (i = 0; i < n; i++) pose(lp + 3 * i, lj + 4 * i, lw + 4 * i, 4, posed + 3 * i);
    for (t = 0; t < m; t++) {
        int s, a;
        for (s = 0; s < 4; s++) {
            double q[3] = {0, 0, 0}, best = 1e30;
            for (a = 0; a < 3; a++) {
                const double *v = posed + 3 * lt[3 * t + a];
                q[0] += bary[s][a] * v[0], q[1] += bary[s][a] * v[1], q[2] += bary[s][a] * v[2];
            }
            for (i = 0; i < NT; i++) {
                double d = point_triangle(q, posed_in + 3 * tri[3 * i], posed_in + 3 * tri[3 * i + 1],
                                          posed_in + 3 * tri[3 * i + 2]);
                best = d < best ? d : best;
            }
            worst = best > worst ? best : worst;
        }
    }
done:
    pleat_transfer_destroy(tr);
    free(lp), free(posed), free(lt), free(lj), free(lw);
    return worst;
}

static void misuse(PleatMesh *input) {
    PleatDeformationDesc d = pleat_deformation_desc_default();
    PleatDeformation *h = NULL;
    PleatMesh *out = NULL;
    PleatLodParams lp = pleat_lod_params_default();
    float bad[2 * NV];
    CHECK_STATUS(pleat_deformation_create(NULL, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_deformation_create(&d, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    d.vertex_count = NV, d.influences = 2, d.joints = joints, d.weights = NULL;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    memcpy(bad, weights, sizeof bad);
    bad[7] = NAN, d.weights = bad;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    bad[7] = -0.5f;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    d.weights = weights, d.influences = 65;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    d.influences = 2, d.vertex_count = (size_t)-1;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    d.vertex_count = NV, d.max_skin_error = NAN;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    d.max_skin_error = 0, d.morph_count = 1, d.morph_deltas = NULL;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(h == NULL);
    /* A deformation of another mesh (one vertex fewer) is refused by the bake. */
    d.morph_count = 0, d.vertex_count = NV - 1;
    CHECK_STATUS(pleat_deformation_create(&d, &h), PLEAT_STATUS_OK);
    lp.screen_size = 50, lp.deformation = h;
    CHECK_STATUS(pleat_lod_generate(input, &lp, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(out == NULL);
    pleat_deformation_destroy(h);
    pleat_deformation_destroy(NULL);
}

int main(void) {
    PleatMesh *input = NULL, *plain = NULL, *bent = NULL;
    PleatDeformation *skin = NULL;
    PleatDeformationDesc desc = pleat_deformation_desc_default();
    PleatLodParams lp = pleat_lod_params_default();
    const double pivots[6] = {0, 0, 0, 0, 1, 0};
    double e_plain, e_bent;
    if (!pleat_has_feature("lod")) return finish("deform_lod (no lod: skipped)");
    tube();
    CHECK_STATUS(pleat_mesh_create_f64(pos, NV, 0, tri, 3 * NT, &input), PLEAT_STATUS_OK);
    /* The skin: two influences per vertex, the joints' pivots, joints turning up to 1 rad. */
    desc.vertex_count = NV, desc.influences = 2, desc.joints = joints, desc.weights = weights;
    desc.joint_count = 2, desc.joint_pivots = pivots, desc.max_rotation = ANGLE;
    CHECK_STATUS(pleat_deformation_create(&desc, &skin), PLEAT_STATUS_OK);
    lp.screen_size = 50;
    CHECK_STATUS(pleat_lod_generate(input, &lp, NULL, NULL, &plain, NULL), PLEAT_STATUS_OK);
    lp.deformation = skin;
    CHECK_STATUS(pleat_lod_generate(input, &lp, NULL, NULL, &bent, NULL), PLEAT_STATUS_OK);
    if (plain && bent) {
        /* l = the tube's bounding-box diagonal; errors printed over l. */
        double l = sqrt(0.6 * 0.6 * 2 + 4.0);
        e_plain = posed_error(input, plain, 50) / l, e_bent = posed_error(input, bent, 50) / l;
        printf("deform_lod: plain %zu faces, posed error %.4f l; following the skin %zu faces, "
               "%.4f l\n", pleat_mesh_triangle_count(plain), e_plain,
               pleat_mesh_triangle_count(bent), e_bent);
        CHECK(e_plain > 0 && e_bent >= 0);
        CHECK(pleat_mesh_triangle_count(bent) > pleat_mesh_triangle_count(plain));
        CHECK(e_bent < 0.5 * e_plain);
        /* within two offset distances d = l / 50 of the posed tube */
        CHECK(e_bent <= 2.0 / 50);
    }
    misuse(input);
    pleat_deformation_destroy(skin);
    pleat_mesh_destroy(plain);
    pleat_mesh_destroy(bent);
    pleat_mesh_destroy(input);
    return finish("deform_lod");
}
