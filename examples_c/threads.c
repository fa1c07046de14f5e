/* The C API from several host threads at once.
 *
 * Four host threads each build their own meshes and wrinkle fields (distinct handles) and call
 * pleat concurrently: a LOD bake, a mesh check and (when built with wrinkles) a wrinkle
 * evaluation. Rounds run with pleat's pool at 1, 2 and 8 worker threads and the default (one
 * per core); every thread's output bytes must equal a single-threaded reference computed
 * first. Then pleat_last_error is shown to be per thread: one thread's failure message does
 * not appear in another thread, and a success on one thread does not clear another's message.
 *
 * Worker threads record results in their own slot only (no shared counters), so the program
 * is race-free under ThreadSanitizer (.ci/asan.sh builds it with -fsanitize=thread).
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <pthread.h>
#include <stdint.h>
#include "wrinkle_util.h"

#define HOSTS 4
#define RING 16
#define TUBE 8

/* One computation's output bytes: LOD positions + indices, wrinkled positions. */
typedef struct {
    double *lod_xyz;
    uint32_t *lod_tri;
    size_t lod_nv, lod_nt;
    double *wr_xyz;
    size_t wr_nv;
    int ok; /* 1 when every call returned PLEAT_STATUS_OK */
    char error[256];
} Output;

static void output_free(Output *o) {
    free(o->lod_xyz);
    free(o->lod_tri);
    free(o->wr_xyz);
    memset(o, 0, sizeof *o);
}

static int output_equal(const Output *a, const Output *b) {
    return a->ok && b->ok && a->lod_nv == b->lod_nv && a->lod_nt == b->lod_nt &&
           a->wr_nv == b->wr_nv &&
           memcmp(a->lod_xyz, b->lod_xyz, 3 * a->lod_nv * sizeof(double)) == 0 &&
           memcmp(a->lod_tri, b->lod_tri, 3 * a->lod_nt * sizeof(uint32_t)) == 0 &&
           (a->wr_nv == 0 || memcmp(a->wr_xyz, b->wr_xyz, 3 * a->wr_nv * sizeof(double)) == 0);
}

static PleatMesh *make_torus(void) {
    double p[3 * RING * TUBE];
    uint32_t t[6 * RING * TUBE];
    int i, j, k = 0;
    PleatMesh *m = NULL;
    for (i = 0; i < RING; i++)
        for (j = 0; j < TUBE; j++) {
            double u = 2 * M_PI * i / RING, v = 2 * M_PI * j / TUBE, r = 1.0 + 0.35 * cos(v);
            p[3 * (i * TUBE + j) + 0] = r * cos(u);
            p[3 * (i * TUBE + j) + 1] = r * sin(u);
            p[3 * (i * TUBE + j) + 2] = 0.35 * sin(v);
        }
    for (i = 0; i < RING; i++)
        for (j = 0; j < TUBE; j++) {
            uint32_t a = (uint32_t)(i * TUBE + j), b = (uint32_t)(((i + 1) % RING) * TUBE + j),
                     c = (uint32_t)(((i + 1) % RING) * TUBE + (j + 1) % TUBE),
                     d = (uint32_t)(i * TUBE + (j + 1) % TUBE);
            t[k++] = a, t[k++] = b, t[k++] = c;
            t[k++] = a, t[k++] = c, t[k++] = d;
        }
    if (pleat_mesh_create_f64(p, RING * TUBE, 0, t, 6 * RING * TUBE, &m) != PLEAT_STATUS_OK)
        return NULL;
    return m;
}

#define TRY(call)                                                                  \
    do {                                                                           \
        PleatStatus st_ = (call);                                                  \
        if (st_ != PLEAT_STATUS_OK) {                                              \
            snprintf(out->error, sizeof out->error, "%s: %d (%s)", #call, (int)st_, \
                     pleat_last_error());                                          \
            goto done;                                                             \
        }                                                                          \
    } while (0)

/* The whole workload on fresh handles; fills `out`. */
static void compute(Output *out) {
    PleatMesh *torus = make_torus(), *lod = NULL, *oct = NULL, *wrinkled = NULL;
    PleatCwf *cwf = NULL;
    PleatLodParams lp = pleat_lod_params_default();
    PleatMeshReport rep;
    memset(out, 0, sizeof *out);
    if (!torus) {
        snprintf(out->error, sizeof out->error, "torus: %s", pleat_last_error());
        return;
    }
    if (pleat_has_feature("lod")) {
        lp.screen_size = 40.0;
        lp.max_rounds = 4;
        TRY(pleat_lod_generate(torus, &lp, NULL, NULL, &lod, NULL));
        out->lod_nv = pleat_mesh_vertex_count(lod);
        out->lod_nt = pleat_mesh_triangle_count(lod);
        out->lod_xyz = (double *)malloc(3 * out->lod_nv * sizeof(double) + 1);
        out->lod_tri = (uint32_t *)malloc(3 * out->lod_nt * sizeof(uint32_t) + 1);
        TRY(pleat_mesh_copy_positions_f64(lod, out->lod_xyz, out->lod_nv, 0));
        TRY(pleat_mesh_copy_indices(lod, out->lod_tri, 3 * out->lod_nt));
        memset(&rep, 0, sizeof rep);
        rep.struct_size = sizeof rep;
        TRY(pleat_mesh_check(lod, 0, &rep));
        if (!(rep.is_watertight && rep.self_intersection_free)) {
            snprintf(out->error, sizeof out->error, "LOD is not watertight and clean");
            goto done;
        }
    }
    if (pleat_has_feature("wrinkle")) {
        const double k[3] = {3.0, 1.0, 2.0};
        PleatWrinkleEvalParams ep = pleat_wrinkle_eval_params_default();
        size_t ne, nv, i;
        double *zeta, *omega, *amp;
        oct = make_octahedron();
        nv = pleat_mesh_vertex_count(oct);
        zeta = (double *)malloc(2 * nv * sizeof(double));
        amp = (double *)malloc(nv * sizeof(double));
        omega = plane_wave(oct, k, &ne, zeta);
        for (i = 0; i < nv; i++) amp[i] = 0.05;
        {
            PleatStatus st = pleat_cwf_create(oct, omega, ne, amp, zeta, nv, &cwf);
            free(zeta), free(amp), free(omega);
            TRY(st);
        }
        ep.levels = 3;
        TRY(pleat_cwf_evaluate(cwf, &ep, NULL, NULL, &wrinkled, NULL, NULL));
        out->wr_nv = pleat_mesh_vertex_count(wrinkled);
        out->wr_xyz = (double *)malloc(3 * out->wr_nv * sizeof(double) + 1);
        TRY(pleat_mesh_copy_positions_f64(wrinkled, out->wr_xyz, out->wr_nv, 0));
    }
    out->ok = 1;
done:
    pleat_mesh_destroy(torus);
    pleat_mesh_destroy(lod);
    pleat_mesh_destroy(oct);
    pleat_mesh_destroy(wrinkled);
    pleat_cwf_destroy(cwf);
}

static void *host_thread(void *arg) {
    compute((Output *)arg);
    return NULL;
}

/* ---- pleat_last_error is per thread ---------------------------------------------------- */

static pthread_barrier_t g_barrier;
static char g_msg0[256]; /* thread 0's message, written before barrier 1 */

typedef struct {
    int id;
    int failures;
    char log[512];
} ErrorProbe;

static void probe_fail(ErrorProbe *p, const char *what) {
    size_t n = strlen(p->log);
    p->failures++;
    snprintf(p->log + n, sizeof p->log - n, "[thread %d] %s; ", p->id, what);
}

/* Thread 0 fails a call (NULL output pointer) and keeps its message while thread 1 succeeds
 * and then fails differently (vertex count 0); each sees only its own message. */
static void *error_thread(void *arg) {
    ErrorProbe *p = (ErrorProbe *)arg;
    static const double xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t tri[3] = {0, 1, 2};
    PleatMesh *m = NULL;
    char mine[256];
    if (p->id == 0) {
        if (pleat_mesh_create_f64(xyz, 3, 0, tri, 3, NULL) != PLEAT_STATUS_INVALID_ARGUMENT)
            probe_fail(p, "NULL out was accepted");
        snprintf(mine, sizeof mine, "%s", pleat_last_error());
        if (mine[0] == '\0') probe_fail(p, "no message after a failure");
        snprintf(g_msg0, sizeof g_msg0, "%s", mine);
        pthread_barrier_wait(&g_barrier); /* 1: thread 1 now succeeds */
        pthread_barrier_wait(&g_barrier); /* 2: thread 1 succeeded */
        if (strcmp(pleat_last_error(), mine) != 0) probe_fail(p, "another thread's success changed my message");
        pthread_barrier_wait(&g_barrier); /* 3: thread 1 now fails differently */
        pthread_barrier_wait(&g_barrier); /* 4: thread 1 failed */
        if (strcmp(pleat_last_error(), mine) != 0) probe_fail(p, "another thread's failure changed my message");
    } else {
        pthread_barrier_wait(&g_barrier); /* 1 */
        if (pleat_mesh_create_f64(xyz, 3, 0, tri, 3, &m) != PLEAT_STATUS_OK)
            probe_fail(p, "a valid mesh was rejected");
        if (pleat_last_error()[0] != '\0') probe_fail(p, "another thread's message is visible here");
        pleat_mesh_destroy(m);
        pthread_barrier_wait(&g_barrier); /* 2 */
        pthread_barrier_wait(&g_barrier); /* 3 */
        if (pleat_mesh_create_f64(xyz, 0, 0, tri, 3, &m) != PLEAT_STATUS_INVALID_ARGUMENT)
            probe_fail(p, "vertex count 0 was accepted");
        snprintf(mine, sizeof mine, "%s", pleat_last_error());
        if (mine[0] == '\0' || strcmp(mine, g_msg0) == 0)
            probe_fail(p, "my message is missing or is thread 0's");
        pthread_barrier_wait(&g_barrier); /* 4 */
    }
    return NULL;
}

int main(void) {
    static const uint32_t counts[4] = {1, 2, 8, 0};
    Output reference, outs[HOSTS];
    pthread_t th[HOSTS];
    ErrorProbe probes[2];
    int round, i;

    CHECK_STATUS(pleat_set_thread_count(1), PLEAT_STATUS_OK);
    compute(&reference);
    if (!reference.ok) fprintf(stderr, "reference: %s\n", reference.error);
    CHECK(reference.ok);
    printf("reference: LOD %zu vertices / %zu triangles, wrinkled %zu vertices\n",
           reference.lod_nv, reference.lod_nt, reference.wr_nv);

    for (round = 0; round < 4; round++) {
        /* the pool is changed only while no pleat call runs (see pleat_set_thread_count) */
        CHECK_STATUS(pleat_set_thread_count(counts[round]), PLEAT_STATUS_OK);
        for (i = 0; i < HOSTS; i++) CHECK(pthread_create(&th[i], NULL, host_thread, &outs[i]) == 0);
        for (i = 0; i < HOSTS; i++) CHECK(pthread_join(th[i], NULL) == 0);
        for (i = 0; i < HOSTS; i++) {
            if (!outs[i].ok) fprintf(stderr, "round %d host %d: %s\n", round, i, outs[i].error);
            CHECK(output_equal(&outs[i], &reference));
            output_free(&outs[i]);
        }
        printf("pool of %u threads (0 = per core), %d host threads: outputs identical\n",
               counts[round], HOSTS);
    }
    output_free(&reference);

    CHECK(pthread_barrier_init(&g_barrier, NULL, 2) == 0);
    for (i = 0; i < 2; i++) {
        memset(&probes[i], 0, sizeof probes[i]);
        probes[i].id = i;
        CHECK(pthread_create(&th[i], NULL, error_thread, &probes[i]) == 0);
    }
    for (i = 0; i < 2; i++) {
        CHECK(pthread_join(th[i], NULL) == 0);
        if (probes[i].failures) fprintf(stderr, "%s\n", probes[i].log);
        CHECK(probes[i].failures == 0);
    }
    pthread_barrier_destroy(&g_barrier);
    CHECK_STATUS(pleat_set_thread_count(0), PLEAT_STATUS_OK);
    return finish("threads");
}
