/* Every documented misuse of the C API returns its status with a message; nothing aborts. */
#include <math.h>
#include "test_util.h"

static const float P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t I[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

static void misuse_create(void) {
    PleatMesh *m = NULL;
    CHECK_STATUS(pleat_mesh_create_f32(NULL, 4, 0, I, 12, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, NULL, 12, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 12, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 0, 0, I, 12, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 0, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 11, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 8, I, 12, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f64((const double *)P, 4, 16, I, 12, &m),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_create_f32(P, 3, 0, I, 12, &m), PLEAT_STATUS_INVALID_MESH);
    {
        float bad[12];
        memcpy(bad, P, sizeof bad);
        bad[4] = NAN;
        CHECK_STATUS(pleat_mesh_create_f32(bad, 4, 0, I, 12, &m), PLEAT_STATUS_INVALID_MESH);
        bad[4] = INFINITY;
        CHECK_STATUS(pleat_mesh_create_f32(bad, 4, 0, I, 12, &m), PLEAT_STATUS_INVALID_MESH);
    }
    {
        uint32_t oob[12];
        memcpy(oob, I, sizeof oob);
        oob[7] = 4;
        CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, oob, 12, &m), PLEAT_STATUS_INVALID_MESH);
        oob[7] = 0xffffffffu;
        CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, oob, 12, &m), PLEAT_STATUS_INVALID_MESH);
    }
    CHECK(m == NULL); /* outputs are written only on success */
    /* a vertex count whose buffer size overflows size_t */
    CHECK_STATUS(pleat_mesh_create_f32(P, (size_t)-1 / 8, 64, I, 12, &m),
                 PLEAT_STATUS_INVALID_ARGUMENT);
}

static void misuse_copy(void) {
    PleatMesh *m = NULL;
    float out[12];
    uint32_t idx[12];
    CHECK_STATUS(pleat_mesh_create_f32(P, 4, 0, I, 12, &m), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_copy_positions_f32(NULL, out, 4, 0), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_copy_positions_f32(m, NULL, 4, 0), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_copy_positions_f32(m, out, 3, 0), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_mesh_copy_positions_f32(m, out, 4, 4), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_copy_indices(m, idx, 11), PLEAT_STATUS_LIMIT_EXCEEDED);
    CHECK_STATUS(pleat_mesh_copy_indices(m, NULL, 12), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_copy_indices(NULL, idx, 12), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(pleat_mesh_vertex_count(NULL) == 0);
    CHECK(pleat_mesh_triangle_count(NULL) == 0);
    pleat_mesh_destroy(m);
    pleat_mesh_destroy(NULL);
}

static void misuse_misc(void) {
    char buf[8];
    size_t needed = 0;
    PleatMesh *m = NULL;
    CHECK_STATUS(pleat_mesh_create_f32(NULL, 4, 0, I, 12, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(pleat_last_error_message(NULL, 0, &needed) == PLEAT_STATUS_OK);
    CHECK(needed == strlen(pleat_last_error()) && needed > 0);
    CHECK(pleat_last_error_message(buf, sizeof buf, NULL) == PLEAT_STATUS_OK);
    CHECK(strlen(buf) == sizeof buf - 1); /* truncated, NUL-terminated */
    CHECK(pleat_last_error_message(NULL, 4, NULL) == PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK(pleat_has_feature(NULL) == 0);
    CHECK(pleat_has_feature("no-such-feature") == 0);
}

int main(void) {
    printf("pleat %s (ABI %u)\n", pleat_version(), pleat_abi_version());
    CHECK(pleat_abi_version() == PLEAT_ABI_VERSION);
    misuse_create();
    misuse_copy();
    misuse_misc();
    return finish("misuse");
}
