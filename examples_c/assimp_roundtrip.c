/* A real client's round trip: import a file with assimp, hand its arrays to pleat, check the
 * mesh, copy it back out, export it with assimp, re-import the export and compare counts.
 * Usage: assimp_roundtrip [input] [output.obj]  (defaults: assets/dirty_two_boxes.obj, a temp file) */
#include <assimp/cexport.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include "test_util.h"

/* Gathers all meshes of an imported scene into flat arrays (vertices of mesh k offset by the
 * vertex count of meshes before it). aiVector3D is three floats, so pleat reads it directly with
 * a 12-byte stride; here we concatenate into one buffer. */
static int gather(const struct aiScene *sc, float **pos, size_t *nv, uint32_t **idx, size_t *ni) {
    size_t v = 0, f = 0, k, i;
    for (k = 0; k < sc->mNumMeshes; k++) {
        v += sc->mMeshes[k]->mNumVertices;
        f += sc->mMeshes[k]->mNumFaces;
    }
    *pos = malloc(v * 3 * sizeof(float));
    *idx = malloc(f * 3 * sizeof(uint32_t));
    if (!*pos || !*idx) return 0;
    *nv = 0;
    *ni = 0;
    for (k = 0; k < sc->mNumMeshes; k++) {
        const struct aiMesh *m = sc->mMeshes[k];
        size_t base = *nv;
        for (i = 0; i < m->mNumVertices; i++) {
            (*pos)[3 * *nv + 0] = m->mVertices[i].x;
            (*pos)[3 * *nv + 1] = m->mVertices[i].y;
            (*pos)[3 * *nv + 2] = m->mVertices[i].z;
            (*nv)++;
        }
        for (i = 0; i < m->mNumFaces; i++) {
            if (m->mFaces[i].mNumIndices != 3) continue; /* points/lines after triangulation */
            (*idx)[(*ni)++] = (uint32_t)(base + m->mFaces[i].mIndices[0]);
            (*idx)[(*ni)++] = (uint32_t)(base + m->mFaces[i].mIndices[1]);
            (*idx)[(*ni)++] = (uint32_t)(base + m->mFaces[i].mIndices[2]);
        }
    }
    return 1;
}

/* Builds a one-mesh assimp scene from pleat's output (owned by us, freed by free_scene). */
static struct aiScene *make_scene(const PleatMesh *mesh) {
    size_t nv = pleat_mesh_vertex_count(mesh), nt = pleat_mesh_triangle_count(mesh), i;
    struct aiScene *sc = calloc(1, sizeof *sc);
    struct aiMesh *m = calloc(1, sizeof *m);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx);
    sc->mRootNode = calloc(1, sizeof *sc->mRootNode);
    sc->mRootNode->mTransformation.a1 = sc->mRootNode->mTransformation.b2 = 1;
    sc->mRootNode->mTransformation.c3 = sc->mRootNode->mTransformation.d4 = 1;
    sc->mRootNode->mNumMeshes = 1;
    sc->mRootNode->mMeshes = calloc(1, sizeof(unsigned int));
    sc->mMaterials = calloc(1, sizeof *sc->mMaterials);
    sc->mMaterials[0] = calloc(1, sizeof **sc->mMaterials);
    sc->mNumMaterials = 1;
    sc->mMeshes = calloc(1, sizeof *sc->mMeshes);
    sc->mMeshes[0] = m;
    sc->mNumMeshes = 1;
    m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    m->mNumVertices = (unsigned)nv;
    m->mVertices = malloc(nv * sizeof *m->mVertices);
    m->mNumFaces = (unsigned)nt;
    m->mFaces = calloc(nt, sizeof *m->mFaces);
    CHECK_STATUS(pleat_mesh_copy_positions_f32(mesh, &m->mVertices[0].x, nv, sizeof(struct aiVector3D)),
                 PLEAT_STATUS_OK);
    CHECK_STATUS(pleat_mesh_copy_indices(mesh, idx, nt * 3), PLEAT_STATUS_OK);
    for (i = 0; i < nt; i++) {
        m->mFaces[i].mNumIndices = 3;
        m->mFaces[i].mIndices = &idx[3 * i];
    }
    return sc;
}

static void free_scene(struct aiScene *sc) {
    struct aiMesh *m = sc->mMeshes[0];
    if (m->mNumFaces) free(m->mFaces[0].mIndices);
    free(m->mFaces);
    free(m->mVertices);
    free(m);
    free(sc->mMeshes);
    free(sc->mMaterials[0]);
    free(sc->mMaterials);
    free(sc->mRootNode->mMeshes);
    free(sc->mRootNode);
    free(sc);
}

int main(int argc, char **argv) {
    const char *in = argc > 1 ? argv[1] : "assets/dirty_two_boxes.obj";
    const char *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char out_default[1024];
    const char *out;
    const struct aiScene *sc = aiImportFile(in, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    const struct aiScene *back;
    float *pos = NULL;
    uint32_t *idx = NULL;
    size_t nv = 0, ni = 0;
    PleatMesh *mesh = NULL;
    struct aiScene *exp;
    snprintf(out_default, sizeof out_default, "%s/pleat_assimp_roundtrip_out.obj", tmp);
    out = argc > 2 ? argv[2] : out_default;
    if (!sc) {
        fprintf(stderr, "assimp cannot import %s: %s\n", in, aiGetErrorString());
        return 1;
    }
    CHECK(gather(sc, &pos, &nv, &idx, &ni));
    CHECK_STATUS(pleat_mesh_create_f32(pos, nv, 0, idx, ni, &mesh), PLEAT_STATUS_OK);
    CHECK(pleat_mesh_triangle_count(mesh) == ni / 3);
    printf("imported %s: %zu vertices, %zu triangles\n", in, nv, ni / 3);
    {
        PleatMeshReport r;
        memset(&r, 0, sizeof r);
        r.struct_size = sizeof r;
        CHECK_STATUS(pleat_mesh_check(mesh, 0, &r), PLEAT_STATUS_OK);
        printf("check: components=%llu boundary_edges=%llu watertight=%u self_intersection_free=%u\n",
               (unsigned long long)r.component_count, (unsigned long long)r.boundary_edge_count,
               r.is_watertight, r.self_intersection_free);
        CHECK(r.triangle_count == ni / 3);
    }
    exp = make_scene(mesh);
    CHECK(aiExportScene(exp, "obj", out, 0) == aiReturn_SUCCESS);
    back = aiImportFile(out, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    CHECK(back != NULL);
    if (back) {
        float *p2 = NULL;
        uint32_t *i2 = NULL;
        size_t nv2 = 0, ni2 = 0;
        CHECK(gather(back, &p2, &nv2, &i2, &ni2));
        printf("re-imported %s: %zu vertices, %zu triangles\n", out, nv2, ni2 / 3);
        CHECK(ni2 == ni && nv2 == nv);
        free(p2);
        free(i2);
        aiReleaseImport(back);
    }
    free_scene(exp);
    pleat_mesh_destroy(mesh);
    free(pos);
    free(idx);
    aiReleaseImport(sc);
    return finish("assimp_roundtrip");
}
