/* Carry an input's per-vertex attributes onto its LOD: a LOD of a torus, then its UVs
 * (interpolated) and two-joint skin weights (blended, top 4, renormalised) on the LOD. */
#include <math.h>
#include "test_util.h"

#define RING 32
#define TUBE 16
#define NV (RING * TUBE)

int main(void) {
    static float pos[3 * NV], uv[2 * NV], w[2 * NV];
    static uint32_t tri[6 * NV], joints[2 * NV];
    PleatMesh *input = NULL, *lod = NULL;
    PleatTransfer *tr = NULL;
    PleatLodParams lp = pleat_lod_params_default();
    PleatTransferParams tp = pleat_transfer_params_default();
    int i, j, k = 0;
    if (!pleat_has_feature("lod")) return finish("transfer (no lod: skipped)");
    for (i = 0; i < RING; i++)
        for (j = 0; j < TUBE; j++) {
            int v = i * TUBE + j;
            double u = 6.283185307179586 * i / RING, t = 6.283185307179586 * j / TUBE;
            pos[3 * v] = (float)((1 + 0.35 * cos(t)) * cos(u));
            pos[3 * v + 1] = (float)((1 + 0.35 * cos(t)) * sin(u));
            pos[3 * v + 2] = (float)(0.35 * sin(t));
            uv[2 * v] = (float)i / RING, uv[2 * v + 1] = (float)j / TUBE;
            /* joint 0 holds the +x half, joint 1 the -x half, blended across x = 0 */
            joints[2 * v] = 0, joints[2 * v + 1] = 1;
            w[2 * v] = (float)(0.5 + 0.5 * tanh(3.0 * pos[3 * v])), w[2 * v + 1] = 1 - w[2 * v];
            tri[k++] = (uint32_t)v, tri[k++] = (uint32_t)(((i + 1) % RING) * TUBE + j);
            tri[k++] = (uint32_t)(((i + 1) % RING) * TUBE + (j + 1) % TUBE);
            tri[k++] = (uint32_t)v, tri[k++] = (uint32_t)(((i + 1) % RING) * TUBE + (j + 1) % TUBE);
            tri[k++] = (uint32_t)(i * TUBE + (j + 1) % TUBE);
        }
    CHECK_STATUS(pleat_mesh_create_f32(pos, NV, 0, tri, 6 * NV, &input), PLEAT_STATUS_OK);
    lp.screen_size = tp.screen_size = 40.0;
    CHECK_STATUS(pleat_lod_generate(input, &lp, NULL, NULL, &lod, NULL), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_transfer_create(input, lod, &tp, &tr), PLEAT_STATUS_OK);
    {
        size_t n = pleat_transfer_lod_vertex_count(tr);
        float *luv = malloc(2 * n * sizeof *luv), *lw = malloc(4 * n * sizeof *lw);
        uint32_t *lj = malloc(4 * n * sizeof *lj);
        CHECK(n == pleat_mesh_vertex_count(lod) && luv && lw && lj);
        CHECK_STATUS(pleat_transfer_f32(tr, PLEAT_TRANSFER_BARYCENTRIC, uv, NV, 2, luv, n),
                     PLEAT_STATUS_OK);
        CHECK_STATUS(pleat_transfer_skin(tr, joints, w, NV, 2, 4, lj, lw, n), PLEAT_STATUS_OK);
        for (k = 0; k < (int)n; k++) {
            float s = lw[4 * k] + lw[4 * k + 1] + lw[4 * k + 2] + lw[4 * k + 3];
            CHECK(fabsf(s - 1.0f) <= 1e-6f && lw[4 * k] >= lw[4 * k + 1] && lj[4 * k] <= 1);
            CHECK(luv[2 * k] >= 0.0f && luv[2 * k] <= 1.0f && lw[4 * k + 2] == 0.0f);
        }
        printf("transfer: %zu LOD vertices got UVs and skin weights\n", n);
        free(luv), free(lw), free(lj);
    }
    pleat_transfer_destroy(tr);
    pleat_mesh_destroy(lod);
    pleat_mesh_destroy(input);
    return finish("transfer");
}
