/* Base meshes and waves shared by the wrinkle programs (wrinkle_eval.c, wrinkle_misuse.c). */
#ifndef PLEAT_WRINKLE_UTIL_H
#define PLEAT_WRINKLE_UTIL_H
#include <math.h>
#include "test_util.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* An n x n-vertex grid on [0,1]^2 in the plane z = 0, triangles counter-clockwise seen from +z.
   Vertex (i, j) has index j*n + i. */
static inline PleatMesh *make_grid(int n) {
    size_t nv = (size_t)n * n, nt = 2 * (size_t)(n - 1) * (n - 1);
    double *p = (double *)malloc(3 * nv * sizeof *p);
    uint32_t *t = (uint32_t *)malloc(3 * nt * sizeof *t);
    PleatMesh *m = NULL;
    int i, j;
    size_t k = 0;
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            p[3 * (j * n + i) + 0] = (double)i / (n - 1);
            p[3 * (j * n + i) + 1] = (double)j / (n - 1);
            p[3 * (j * n + i) + 2] = 0.0;
        }
    for (j = 0; j + 1 < n; j++)
        for (i = 0; i + 1 < n; i++) {
            uint32_t v00 = (uint32_t)(j * n + i), v10 = v00 + 1, v01 = v00 + (uint32_t)n,
                     v11 = v01 + 1;
            t[k++] = v00, t[k++] = v10, t[k++] = v11;
            t[k++] = v00, t[k++] = v11, t[k++] = v01;
        }
    if (pleat_mesh_create_f64(p, nv, 0, t, 3 * nt, &m) != PLEAT_STATUS_OK)
        fprintf(stderr, "make_grid: %s\n", pleat_last_error());
    free(p);
    free(t);
    return m;
}

/* The regular octahedron with vertices +-x, +-y, +-z (closed, outward-oriented). */
static inline PleatMesh *make_octahedron(void) {
    static const double p[] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    static const uint32_t t[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                                 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    PleatMesh *m = NULL;
    if (pleat_mesh_create_f64(p, 6, 0, t, 24, &m) != PLEAT_STATUS_OK)
        fprintf(stderr, "make_octahedron: %s\n", pleat_last_error());
    return m;
}

/* The positions of `m` (3 doubles per vertex; free with free()). */
static inline double *positions_of(const PleatMesh *m) {
    size_t n = pleat_mesh_vertex_count(m);
    double *p = (double *)malloc(3 * n * sizeof *p + 1);
    pleat_mesh_copy_positions_f64(m, p, n, 0);
    return p;
}

/* The edges of `m` in pleat's numbering (2 indices per edge; free with free()). */
static inline uint32_t *edges_of(const PleatMesh *m, size_t *edge_count) {
    size_t n = pleat_mesh_edge_count(m);
    uint32_t *e = (uint32_t *)malloc(2 * n * sizeof *e + 1);
    pleat_mesh_copy_edges(m, e, n);
    *edge_count = n;
    return e;
}

static inline double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The plane wave of wave vector k: omega_ij = k.(x_j - x_i) on each edge i<j (free with
   free()), and, when zeta is non-NULL, zeta_j = exp(i k.x_j) (2 doubles per vertex). */
static inline double *plane_wave(const PleatMesh *m, const double k[3], size_t *edge_count,
                                 double *zeta) {
    double *x = positions_of(m);
    uint32_t *e = edges_of(m, edge_count);
    double *w = (double *)malloc(*edge_count * sizeof *w + 1);
    size_t i, n = pleat_mesh_vertex_count(m);
    for (i = 0; i < *edge_count; i++) {
        const double *a = x + 3 * e[2 * i], *b = x + 3 * e[2 * i + 1];
        double d[3];
        d[0] = b[0] - a[0], d[1] = b[1] - a[1], d[2] = b[2] - a[2];
        w[i] = dot3(k, d);
    }
    if (zeta)
        for (i = 0; i < n; i++) {
            double phi = dot3(k, x + 3 * i);
            zeta[2 * i] = cos(phi);
            zeta[2 * i + 1] = sin(phi);
        }
    free(x);
    free(e);
    return w;
}

/* x - 2 pi round(x / 2 pi): the representative in [-pi, pi]. */
static inline double wrap_pi(double x) { return x - 2 * M_PI * floor(x / (2 * M_PI) + 0.5); }

static inline double *filled(size_t n, double v) {
    double *a = (double *)malloc(n * sizeof *a + 1);
    size_t i;
    for (i = 0; i < n; i++) a[i] = v;
    return a;
}
#endif
