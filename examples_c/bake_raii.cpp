// The C++ RAII wrapper (bindings/cpp/pleat.hpp) for textured LODs: provenance, a bake with a
// procedural texture, copies out, cancellation and errors as exceptions, moves.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>
#include "pleat.hpp"

static int failures = 0, checks = 0;
#define EXPECT(c)                                                                        \
    do {                                                                                 \
        checks++;                                                                        \
        if (!(c)) {                                                                      \
            failures++;                                                                  \
            std::fprintf(stderr, "%s:%d: EXPECT failed: %s\n", __FILE__, __LINE__, #c); \
        }                                                                                \
    } while (0)

// A unit UV sphere, seam and poles duplicated, per-vertex UVs.
static void sphere(int slices, int stacks, std::vector<float> &p, std::vector<float> &uv,
                   std::vector<uint32_t> &t) {
    const double pi = 3.141592653589793;
    for (int j = 0; j <= stacks; j++)
        for (int i = 0; i <= slices; i++) {
            double u = double(i) / slices, v = double(j) / stacks;
            double th = 2 * pi * u, ph = pi * v;
            p.insert(p.end(), {float(std::sin(ph) * std::cos(th)),
                               float(std::sin(ph) * std::sin(th)), float(std::cos(ph))});
            uv.insert(uv.end(), {float(u), float(v)});
        }
    for (int j = 0; j < stacks; j++)
        for (int i = 0; i < slices; i++) {
            uint32_t a = uint32_t(j * (slices + 1) + i), c = a + uint32_t(slices) + 1;
            t.insert(t.end(), {a, c, c + 1, a, c + 1, a + 1});
        }
}

int main() {
    if (!pleat::has_feature("bake")) {
        std::printf("bake_raii: SKIPPED (no `bake` capability)\n");
        return 0;
    }
    std::vector<float> p, uv;
    std::vector<uint32_t> t;
    sphere(24, 12, p, uv, t);
    const int n = 32;
    std::vector<uint8_t> tex(4 * n * n);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            uint8_t *px = &tex[size_t(4 * (y * n + x))];
            px[0] = uint8_t(255 * x / (n - 1));
            px[1] = ((x / 8 + y / 8) % 2) ? 200 : 40;
            px[2] = uint8_t(255 - 255 * y / (n - 1));
            px[3] = 255;
        }
    pleat::Mesh input = pleat::Mesh::from_arrays(p.data(), p.size() / 3, t.data(), t.size());
    PleatLodParams lp = pleat::lod_params(50.0);
    lp.max_rounds = 6;
    pleat::Mesh lod = input.lod(lp);

    PleatProvenanceParams pp = pleat_provenance_params_default();
    pp.screen_size = 50.0;
    pleat::Provenance prov = pleat::lod_provenance(lod, input, pp);
    EXPECT(prov.triangle.size() == lod.vertex_count());
    for (size_t i = 0; i < prov.triangle.size(); i++) {
        EXPECT(prov.triangle[i] < input.triangle_count());
        EXPECT(std::fabs(prov.bary[3 * i] + prov.bary[3 * i + 1] + prov.bary[3 * i + 2] - 1) <
               1e-9);
    }
    pleat::Provenance top = pleat::points_provenance(input, {0, 0, 1.5});
    EXPECT(top.triangle.size() == 1 && top.by_ray[0] == 0);

    PleatBakeMaterial m = pleat_bake_material_default();
    m.uvs = uv.data();
    m.uv_count = uv.size() / 2;
    m.base_color = PleatImage{tex.data(), uint32_t(n), uint32_t(n), 1, 0};
    PleatBakeParams bp = pleat::bake_params(50.0);
    bp.texture_size = 64;
    bp.error_samples = 200;
    int calls = 0;
    pleat::Bake b = pleat::Bake::make(lod, input, m, bp, [&](const char *, double) {
        calls++;
        return true;
    });
    EXPECT(b && calls > 0 && b.textured());
    std::vector<float> uvs = b.uvs();
    EXPECT(uvs.size() == 2 * b.vertex_count());
    for (float c : uvs) EXPECT(c >= 0.0f && c <= 1.0f);
    EXPECT(b.indices().size() == 3 * b.triangle_count() && b.tangents().size() == 4 * b.vertex_count());
    uint32_t w = 0, h = 0;
    std::vector<uint8_t> img = b.image(PLEAT_BAKE_IMAGE_BASE_COLOR, w, h);
    EXPECT(w == 64 && h == 64 && img.size() == 4 * 64 * 64);
    EXPECT(b.image(PLEAT_BAKE_IMAGE_OCCLUSION, w, h).empty() && w == 0);
    PleatBakeStats st = b.stats();
    EXPECT(st.charts > 0 && st.texture_size == 64);
    std::printf("bake: %zu vertices, %u charts, error mean %.2f /255\n", b.vertex_count(),
                st.charts, st.appearance_error_mean);
    pleat::Bake moved = std::move(b);
    EXPECT(!b && moved);
    try {
        (void)moved.colors();
        EXPECT(false);
    } catch (const pleat::Error &e) {
        EXPECT(e.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: no colours -> %s\n", e.what());
    }
    try {
        pleat::Bake::make(lod, input, m, bp, [](const char *stage, double) {
            return std::strcmp(stage, "bake: texels") != 0;
        });
        EXPECT(false);
    } catch (const pleat::Error &e) {
        EXPECT(e.status() == PLEAT_STATUS_CANCELLED);
        std::printf("  ok: cancelled -> %s\n", e.what());
    }
    {
        // Two materials: the checker and an untextured green, one per half of the triangles.
        PleatBakeMaterial green = pleat_bake_material_default();
        green.base_color_factor[0] = green.base_color_factor[2] = 0.0;
        std::vector<uint32_t> tm(input.triangle_count());
        for (size_t i = 0; i < tm.size(); i++) tm[i] = i < tm.size() / 2 ? 0 : 1;
        pleat::Bake two = pleat::Bake::make(lod, input, {m, green}, tm, bp);
        EXPECT(two && two.textured());
        tm[0] = 2;
        try {
            pleat::Bake::make(lod, input, {m, green}, tm, bp);
            EXPECT(false);
        } catch (const pleat::Error &e) {
            EXPECT(e.status() == PLEAT_STATUS_INVALID_ARGUMENT);
            std::printf("  ok: material index out of range -> %s\n", e.what());
        }
    }
    try {
        m.uv_count = 3;
        pleat::Bake::make(lod, input, m, bp);
        EXPECT(false);
    } catch (const pleat::Error &e) {
        EXPECT(e.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: short UVs -> %s\n", e.what());
    }
    std::printf("bake_raii: %d passed, %d failed\n", checks - failures, failures);
    return failures == 0 ? 0 : 1;
}
