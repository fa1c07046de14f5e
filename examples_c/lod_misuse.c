/* Misuse of the LOD and cage calls returns a status with a message; nothing aborts and no
 * output is written. */
#include <math.h>
#include "test_util.h"

static const float P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t I[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

int main(void) {
    PleatMesh *m = NULL, *out = NULL;
    PleatMesh *outs[2] = {NULL, NULL};
    PleatLodParams p = pleat_lod_params_default();
    PleatLodStats st;
    const double sizes[2] = {10.0, NAN};
    const int lod = (int)pleat_has_feature("lod");
    CHECK(p.struct_size == sizeof p && p.screen_size == 200.0 && p.max_rounds == 50);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 12, &m), PLEAT_STATUS_OK);
    if (!lod) {
        CHECK_STATUS(pleat_lod_generate(m, NULL, NULL, NULL, &out, NULL),
                     PLEAT_STATUS_UNSUPPORTED);
        pleat_mesh_destroy(m);
        return finish("lod_misuse");
    }
    CHECK_STATUS(pleat_lod_generate(NULL, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p.screen_size = NAN;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* a build with "lod" but without "cage" answers UNSUPPORTED before looking at params */
    CHECK_STATUS(pleat_cage_generate(m, &p, NULL, NULL, &out, NULL),
                 pleat_has_feature("cage") ? PLEAT_STATUS_INVALID_ARGUMENT
                                           : PLEAT_STATUS_UNSUPPORTED);
    p.screen_size = -1.0;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_lod_params_default();
    p.struct_size = 0;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_lod_params_default();
    p.flow_ratio = 2.0;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_lod_params_default();
    p.flags = 0x80;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_lod_params_default();
    p.target_faces = 3;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    p = pleat_lod_params_default();
    p.memory_budget_bytes = 100;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_LIMIT_EXCEEDED);
    p = pleat_lod_params_default();
    memset(&st, 0, sizeof st); /* struct_size 0 */
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, &st),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(out == NULL);
    /* chains */
    CHECK_STATUS(pleat_lod_generate_chain(m, NULL, 2, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_generate_chain(m, sizes, 0, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_generate_chain(m, sizes, 2, &p, NULL, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_lod_generate_chain(m, sizes, 2, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT); /* NaN screen size */
    CHECK_STATUS(pleat_lod_generate_chain(NULL, sizes, 1, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(outs[0] == NULL && outs[1] == NULL);
    pleat_mesh_destroy(m);
    return finish("lod_misuse");
}
