/* Misuse of the transfer calls returns a status with a message naming the argument; nothing
 * aborts and no output is written. */
#include <math.h>
#include <stdint.h>
#include "test_util.h"

/* A tetrahedron and a copy moved by 1e-3 (its "LOD" at n_p = 10), and a far copy. */
static const float P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const float Q[] = {1e-3f, 0, 0, 1.001f, 0, 0, 1e-3f, 1, 0, 1e-3f, 0, 1};
static const float FAR[] = {5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1};
static const uint32_t I[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

#define CHECK_NAMES(field) CHECK(strstr(pleat_last_error(), (field)) != NULL)

int main(void) {
    PleatMesh *in = NULL, *lod = NULL, *far = NULL;
    PleatTransfer *tr = NULL, *none = NULL;
    PleatTransferParams p = pleat_transfer_params_default();
    float vals[8] = {0, 1, 2, 3, 4, 5, 6, 7}, out[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
    float w[8] = {1, 0, 1, 0, 1, 0, 1, 0}, ow[16];
    uint32_t j[8] = {0, 1, 0, 1, 0, 1, 0, 1}, oj[16], ids[4] = {1, 2, 3, 4}, oid[4];
    CHECK(p.struct_size == sizeof p && p.screen_size == 200.0 && p.envelope_d == 3.0);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 12, &in), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_create_f32(Q, 4, 0, I, 12, &lod), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_create_f32(FAR, 4, 0, I, 12, &far), PLEAT_STATUS_OK);
    if (!pleat_has_feature("lod")) {
        CHECK_STATUS(pleat_transfer_create(in, lod, NULL, &tr), PLEAT_STATUS_UNSUPPORTED);
        pleat_mesh_destroy(in), pleat_mesh_destroy(lod), pleat_mesh_destroy(far);
        return finish("transfer_misuse");
    }
    p.screen_size = 10.0;
    /* NULL pointers */
    CHECK_STATUS(pleat_transfer_create(NULL, lod, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("input");
    CHECK_STATUS(pleat_transfer_create(in, NULL, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_create(in, lod, &p, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    /* bad parameters */
    p.screen_size = NAN;
    CHECK_STATUS(pleat_transfer_create(in, lod, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->screen_size");
    p = pleat_transfer_params_default(), p.screen_size = 10.0, p.lookup = 7;
    CHECK_STATUS(pleat_transfer_create(in, lod, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("params->lookup");
    p.lookup = 0, p.struct_size = 4;
    CHECK_STATUS(pleat_transfer_create(in, lod, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("struct_size");
    p = pleat_transfer_params_default(), p.screen_size = 10.0;
    /* a mesh that is not that LOD's input */
    CHECK_STATUS(pleat_transfer_create(far, lod, &p, &tr), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("not the mesh this LOD was made from");
    CHECK(tr == NULL);
    CHECK_STATUS(pleat_transfer_create(in, lod, &p, &tr), PLEAT_STATUS_OK);
    CHECK(pleat_transfer_lod_vertex_count(tr) == 4 && pleat_transfer_input_vertex_count(tr) == 4);
    CHECK(pleat_transfer_lod_vertex_count(NULL) == 0);
    /* NULL handle and arrays */
    CHECK_STATUS(pleat_transfer_f32(NULL, 0, vals, 4, 2, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("transfer");
    CHECK_STATUS(pleat_transfer_f32(tr, 0, NULL, 4, 2, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("values");
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 4, 2, NULL, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("out_values");
    CHECK_STATUS(pleat_transfer_u32(tr, NULL, 4, 1, oid, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_skin(tr, j, NULL, 4, 2, 4, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("weights");
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 4, oj, NULL, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    /* size mismatch, k = 0, huge counts, unknown mode */
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 3, 2, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("n_input");
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 4, 2, out, 5), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("n_lod");
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 4, 0, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("k is 0");
    CHECK_STATUS(pleat_transfer_u32(tr, ids, 4, 0, oid, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, SIZE_MAX, 2, out, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 4, SIZE_MAX / 2, out, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, SIZE_MAX, 4, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_transfer_f32(tr, 9, vals, 4, 2, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("mode");
    /* NaN values, negative weights, too many influences, a vertex without weight */
    vals[5] = NAN;
    CHECK_STATUS(pleat_transfer_f32(tr, 0, vals, 4, 2, out, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("values[5]");
    vals[5] = 5;
    w[2] = -1;
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 4, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("weights[2]");
    w[2] = 0;
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 4, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("no positive skin weight");
    w[2] = 1;
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 5, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_NAMES("max_influences");
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 0, oj, ow, 4),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(out[0] == -1 && out[7] == -1); /* nothing written on failure */
    /* and the right calls work */
    CHECK_STATUS(pleat_transfer_f32(tr, PLEAT_TRANSFER_NEAREST, vals, 4, 2, out, 4),
                 PLEAT_STATUS_OK);
    CHECK(out[0] == 0 && out[7] == 7);
    CHECK_STATUS(pleat_transfer_u32(tr, ids, 4, 1, oid, 4), PLEAT_STATUS_OK);
    CHECK(oid[0] == 1 && oid[3] == 4);
    CHECK_STATUS(pleat_transfer_skin(tr, j, w, 4, 2, 4, oj, ow, 4), PLEAT_STATUS_OK);
    CHECK(oj[0] == 0 && ow[0] == 1.0f && ow[1] == 0.0f);
    pleat_transfer_destroy(tr);
    pleat_transfer_destroy(none); /* NULL is ignored */
    pleat_mesh_destroy(in), pleat_mesh_destroy(lod), pleat_mesh_destroy(far);
    return finish("transfer_misuse");
}
