/* Build meshes from arrays, check them, print and assert on the report. */
#include "test_util.h"

/* A unit cube, outward counter-clockwise triangles; vertex index = 4x + 2y + z. */
static const double CUBE_P[] = {0, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1,
                                1, 0, 0, 1, 0, 1, 1, 1, 0, 1, 1, 1};
static const uint32_t CUBE_T[] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                  2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};

static void print_report(const char *name, const PleatMeshReport *r) {
    printf("%s: V=%llu F=%llu E=%llu components=%llu boundary=%llu nonmanifold_edges=%llu "
           "nonmanifold_vertices=%llu watertight=%u manifold=%u oriented=%u genus=%lld "
           "self_intersection_free=%u (%llu pairs) area=%g volume=%g diag=%g\n",
           name, (unsigned long long)r->vertex_count, (unsigned long long)r->triangle_count,
           (unsigned long long)r->edge_count, (unsigned long long)r->component_count,
           (unsigned long long)r->boundary_edge_count,
           (unsigned long long)r->nonmanifold_edge_count,
           (unsigned long long)r->nonmanifold_vertex_count, r->is_watertight, r->is_manifold,
           r->consistently_oriented, (long long)r->total_genus, r->self_intersection_free,
           (unsigned long long)r->self_intersecting_pair_count, r->surface_area,
           r->signed_volume, r->bbox_diagonal);
}

static void check_cube(void) {
    PleatMesh *m = NULL;
    PleatMeshReport r;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_create_f64(CUBE_P, 8, 0, CUBE_T, 36, &m), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_OK);
    print_report("cube", &r);
    CHECK(r.struct_size == sizeof r);
    CHECK(r.vertex_count == 8 && r.triangle_count == 12 && r.edge_count == 18);
    CHECK(r.component_count == 1 && r.boundary_edge_count == 0);
    CHECK(r.is_watertight == 1 && r.is_manifold == 1 && r.consistently_oriented == 1);
    CHECK(r.total_genus == 0 && r.euler_characteristic == 2);
    CHECK(r.self_intersections_checked == 1 && r.self_intersection_free == 1);
    CHECK(r.surface_area > 5.999 && r.surface_area < 6.001);
    CHECK(r.signed_volume > 0.999 && r.signed_volume < 1.001);
    pleat_mesh_destroy(m);
}

/* Two cubes, the second shifted by half a unit (interpenetrating), plus a duplicated face. */
static void check_dirty(void) {
    double p[48];
    uint32_t t[75];
    int i;
    PleatMesh *m = NULL;
    PleatMeshReport r;
    for (i = 0; i < 24; i++) {
        p[i] = CUBE_P[i];
        p[24 + i] = CUBE_P[i] + 0.5;
    }
    for (i = 0; i < 36; i++) {
        t[i] = CUBE_T[i];
        t[36 + i] = CUBE_T[i] + 8;
    }
    t[72] = CUBE_T[0];
    t[73] = CUBE_T[1];
    t[74] = CUBE_T[2];
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_create_f64(p, 16, 0, t, 75, &m), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_OK);
    print_report("dirty", &r);
    CHECK(r.component_count == 2);
    CHECK(r.nonmanifold_edge_count == 3 && r.duplicate_face_count == 1);
    CHECK(r.is_watertight == 0 && r.is_manifold == 0);
    CHECK(r.self_intersection_free == 0 && r.self_intersecting_pair_count > 0);
    /* skipping the self-intersection pass */
    CHECK_STATUS(pleat_mesh_check(m, PLEAT_CHECK_SKIP_SELF_INTERSECTIONS, &r), PLEAT_STATUS_OK);
    CHECK(r.self_intersections_checked == 0 && r.self_intersecting_pair_count == 0);
    /* an older caller that knows only the first fields */
    {
        PleatMeshReport small;
        memset(&small, 0xAB, sizeof small);
        small.struct_size = 24;
        CHECK_STATUS(pleat_mesh_check(m, 0, &small), PLEAT_STATUS_OK);
        CHECK(small.struct_size == 24 && small.vertex_count == 16);
        CHECK(small.triangle_count == 0xABABABABABABABABull); /* untouched past struct_size */
    }
    /* misuse */
    CHECK_STATUS(pleat_mesh_check(NULL, 0, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_check(m, 0, NULL), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_check(m, 0x100, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    r.struct_size = 0;
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_mesh_destroy(m);
}

static void check_file(void) {
    PleatMesh *m = NULL;
    PleatMeshReport r;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_read_file("assets/dirty_two_boxes.obj", &m), PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_check(m, 0, &r), PLEAT_STATUS_OK);
    print_report("assets/dirty_two_boxes.obj", &r);
    CHECK(r.component_count == 3 && r.boundary_edge_count == 4);
    CHECK(r.is_watertight == 0 && r.self_intersection_free == 0);
    CHECK_STATUS(pleat_mesh_read_file("assets/no_such_file.obj", &m), PLEAT_STATUS_IO);
    CHECK_STATUS(pleat_mesh_read_file(NULL, &m), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_read_file("assets/dirty_two_boxes.obj", NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_write_file(m, "target/x.unknown_ext"), PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_write_file(NULL, "target/x.obj"), PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_mesh_destroy(m);
}

/* Counts progress calls and answers "cancel" (non-zero) from call `cancel_at` on (0: never). */
typedef struct {
    int calls, cancel_at;
    double last_fraction;
    int backwards;
} Counter;

static int count_calls(void *user_data, const PleatProgress *info) {
    Counter *c = user_data;
    c->calls++;
    if (info->fraction < c->last_fraction) c->backwards++;
    c->last_fraction = info->fraction;
    CHECK(info->stage != NULL && strcmp(info->stage, "check") == 0);
    return c->cancel_at > 0 && c->calls >= c->cancel_at;
}

/* pleat_mesh_check_with_progress: the same report as pleat_mesh_check with or without a
 * callback, progress calls with non-decreasing fractions, a cancel from the callback gives
 * PLEAT_STATUS_CANCELLED and leaves the output untouched (valgrind checks for leaks). */
static void check_progress(void) {
    double p[48];
    uint32_t t[72];
    int i, k, calls;
    PleatMesh *m = NULL;
    PleatMeshReport plain, r;
    Counter c = {0, 0, 0.0, 0};
    for (i = 0; i < 24; i++) {
        p[i] = CUBE_P[i];
        p[24 + i] = CUBE_P[i] + 0.5;
    }
    for (i = 0; i < 36; i++) {
        t[i] = CUBE_T[i];
        t[36 + i] = CUBE_T[i] + 8;
    }
    CHECK_STATUS(pleat_mesh_create_f64(p, 16, 0, t, 72, &m), PLEAT_STATUS_OK);
    memset(&plain, 0, sizeof plain);
    plain.struct_size = sizeof plain;
    CHECK_STATUS(pleat_mesh_check(m, PLEAT_CHECK_WELD, &plain), PLEAT_STATUS_OK);
    /* NULL callback */
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check_with_progress(m, PLEAT_CHECK_WELD, NULL, NULL, &r),
                 PLEAT_STATUS_OK);
    CHECK(memcmp(&r, &plain, sizeof r) == 0);
    /* counting callback */
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    CHECK_STATUS(pleat_mesh_check_with_progress(m, PLEAT_CHECK_WELD, count_calls, &c, &r),
                 PLEAT_STATUS_OK);
    CHECK(memcmp(&r, &plain, sizeof r) == 0);
    printf("check with progress: %d calls, last fraction %g\n", c.calls, c.last_fraction);
    CHECK(c.calls >= 7 && c.backwards == 0 && c.last_fraction <= 1.0);
    calls = c.calls;
    /* cancel at the first, a middle and the last call */
    for (k = 0; k < 3; k++) {
        Counter cc = {0, 0, 0.0, 0};
        cc.cancel_at = k == 0 ? 1 : k == 1 ? calls / 2 : calls;
        memset(&r, 0xAB, sizeof r);
        r.struct_size = sizeof r;
        CHECK_STATUS(pleat_mesh_check_with_progress(m, 0, count_calls, &cc, &r),
                     PLEAT_STATUS_CANCELLED);
        CHECK(cc.calls == cc.cancel_at);
        CHECK(r.vertex_count == 0xABABABABABABABABull); /* not written */
    }
    /* misuse, as pleat_mesh_check */
    CHECK_STATUS(pleat_mesh_check_with_progress(NULL, 0, count_calls, &c, &r),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_check_with_progress(m, 0, NULL, NULL, NULL),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(pleat_mesh_check_with_progress(m, 0x100, NULL, NULL, &r),
                 PLEAT_STATUS_INVALID_ARGUMENT);
    pleat_mesh_destroy(m);
}

int main(void) {
    check_cube();
    check_dirty();
    check_file();
    check_progress();
    return finish("check_mesh");
}
