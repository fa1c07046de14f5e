/* Misuse of the LOD and cage calls returns a status with a message; nothing aborts and no
 * output is written. */
#include <math.h>
#include <stddef.h>
#include "test_util.h"

static const float P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t I[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

/* The last error message names the offending field. */
#define CHECK_NAMES(field) CHECK(strstr(pleat_last_error(), (field)) != NULL)

/* Every appended field of PleatLodParams (start, reserved, offset_voxel_scale) rejects what it
 * does not define, with a message naming it, for single LODs and chains alike. */
static void check_appended_fields(PleatMesh *m, PleatMesh *open_sheet) {
    PleatMesh *out = NULL;
    PleatMesh *outs[1] = {NULL};
    const double size[1] = {10.0};
    const double bad_scales[] = {NAN, -1.0, INFINITY, -INFINITY, 2.5, 1e300, -0.0 - 1e-300};
    PleatLodParams p = pleat_lod_params_default();
    CHECK(p.start == PLEAT_LOD_START_AUTO && p.reserved == 0 && p.offset_voxel_scale == 0.0);
    p.start = 3;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->start");
    p.start = 0xFFFFFFFFu;
    CHECK_STATUS(pleat_lod_generate_chain(m, size, 1, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->start");
    p = pleat_lod_params_default();
    p.reserved = 1;
    CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->reserved");
    p.reserved = 0x80000000u;
    CHECK_STATUS(pleat_lod_generate_chain(m, size, 1, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->reserved");
    if (pleat_has_feature("cage")) {
        CHECK_STATUS(pleat_cage_generate(m, &p, NULL, NULL, &out, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_NAMES("params->reserved");
    }
    for (size_t i = 0; i < sizeof bad_scales / sizeof bad_scales[0]; i++) {
        p = pleat_lod_params_default();
        p.offset_voxel_scale = bad_scales[i];
        CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &out, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_NAMES("params->offset_voxel_scale");
        CHECK_STATUS(pleat_lod_generate_chain(m, size, 1, &p, NULL, NULL, outs, NULL),
                     PLEAT_STATUS_INVALID_ARGUMENT);
        CHECK_NAMES("params->offset_voxel_scale");
    }
    /* start = input on an input that is not clean (an open sheet) is refused, not quietly
     * switched to the offset */
    p = pleat_lod_params_default();
    p.screen_size = 10.0;
    p.start = PLEAT_LOD_START_INPUT;
    CHECK_STATUS(pleat_lod_generate(open_sheet, &p, NULL, NULL, &out, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("start = input");
    CHECK_STATUS(pleat_lod_generate_chain(open_sheet, size, 1, &p, NULL, NULL, outs, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("start = input");
    CHECK(out == NULL && outs[0] == NULL);
}

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
    {
        PleatMesh *sheet = NULL;
        CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 3, &sheet), PLEAT_STATUS_OK);
        check_appended_fields(m, sheet);
        pleat_mesh_destroy(sheet);
    }
    {
        /* An older, shorter PleatLodStats (before the fields appended 2026-11-29) is still
           accepted and filled only up to its size. */
        PleatLodStats old;
        PleatMesh *lodm = NULL;
        const uint32_t old_size = (uint32_t)offsetof(PleatLodStats, started_from_finer);
        memset(&old, 0xAB, sizeof old);
        old.struct_size = old_size;
        p = pleat_lod_params_default();
        p.screen_size = 10.0;
        p.max_rounds = 2;
        CHECK_STATUS(pleat_lod_generate(m, &p, NULL, NULL, &lodm, &old), PLEAT_STATUS_OK);
        CHECK(old.struct_size == old_size);
        CHECK(lodm != NULL && old.face_count == pleat_mesh_triangle_count(lodm));
        CHECK(old.started_from_finer == 0xABABABABu && old.stalled == 0xABABABABu);
        CHECK(old.chain_level == (int64_t)0xABABABABABABABABull);
        pleat_mesh_destroy(lodm);
    }
    pleat_mesh_destroy(m);
    return finish("lod_misuse");
}
