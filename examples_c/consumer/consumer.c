#include <stdio.h>
#include <pleat.h>

int main(void) { /* bake a LOD of a unit cube for 20 pixels on screen */
    const float p[] = {0,0,0, 1,0,0, 1,1,0, 0,1,0, 0,0,1, 1,0,1, 1,1,1, 0,1,1};
    const uint32_t t[] = {0,2,1, 0,3,2, 4,5,6, 4,6,7, 0,1,5, 0,5,4, 1,2,6, 1,6,5, 2,3,7, 2,7,6, 3,0,4, 3,4,7};
    PleatMesh *cube = NULL, *lod = NULL;
    PleatLodParams params = pleat_lod_params_default();
    params.screen_size = 20; /* pixels covered by the bounding-box diagonal */
    if (pleat_mesh_create_f32(p, 8, 0, t, 36, &cube) != PLEAT_STATUS_OK ||
        pleat_lod_generate(cube, &params, NULL, NULL, &lod, NULL) != PLEAT_STATUS_OK) {
        fprintf(stderr, "pleat failed: %s\n", pleat_last_error());
        return 1;
    }
    printf("pleat %s: LOD with %zu triangles\n", pleat_version(), pleat_mesh_triangle_count(lod));
    pleat_mesh_destroy(lod);
    pleat_mesh_destroy(cube);
    return 0;
}
