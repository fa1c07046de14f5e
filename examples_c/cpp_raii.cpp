// The C++ RAII wrapper: create, copy out, errors as exceptions, moves.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include "pleat.hpp"

static int failures = 0, checks = 0;
#define EXPECT(c)                                                            \
    do {                                                                     \
        checks++;                                                            \
        if (!(c)) {                                                          \
            failures++;                                                      \
            std::fprintf(stderr, "%s:%d: EXPECT failed: %s\n", __FILE__, __LINE__, #c); \
        }                                                                    \
    } while (0)

// pleat::Cwf: a plane wave on the tetrahedron, evaluated with fields, progress and errors.
static void wrinkles(const pleat::Mesh &base) {
    const double k[3] = {3.0, -2.0, 1.0};
    std::vector<double> x = base.positions(), omega, amp(base.vertex_count(), 0.05), zeta;
    std::vector<uint32_t> e = base.edges();
    EXPECT(e.size() == 2 * 6 && base.edge_count() == 6 && e[0] == 0 && e[1] == 1);
    auto phase = [&](uint32_t v) { return k[0] * x[3 * v] + k[1] * x[3 * v + 1] + k[2] * x[3 * v + 2]; };
    for (size_t i = 0; i < e.size(); i += 2) omega.push_back(phase(e[i + 1]) - phase(e[i]));
    for (uint32_t v = 0; v < base.vertex_count(); v++) {
        zeta.push_back(std::cos(phase(v)));
        zeta.push_back(std::sin(phase(v)));
    }
    if (!pleat_has_feature("wrinkle")) {
        try {
            pleat::Cwf::from_edge_omega(base, omega, amp, zeta);
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_UNSUPPORTED);
            std::printf("SKIPPED: wrinkle (built without it) -> %s\n", err.what());
        }
        return;
    }
    pleat::Cwf cwf = pleat::Cwf::from_edge_omega(base, omega, amp, zeta);
    EXPECT(cwf.vertex_count() == 4 && cwf.edge_count() == 6 && cwf.omega() == omega);
    pleat::Mesh coarse = cwf.evaluate(2);
    EXPECT(coarse.triangle_count() == 4 * 16);

    PleatWrinkleEvalParams p = pleat_wrinkle_eval_params_default();
    p.levels = 3;
    p.flags = PLEAT_WRINKLE_FIELD_PHASE | PLEAT_WRINKLE_FIELD_NORMALS;
    PleatWrinkleEvalStats stats{};
    stats.struct_size = sizeof stats;
    pleat::WrinkleFields fields;
    int calls = 0;
    pleat::Mesh fine = cwf.evaluate(p, &fields, &stats, [&](const char *, double) {
        calls++;
        return true;
    });
    EXPECT(fine.triangle_count() == 4 * 64 && stats.triangle_count == 4 * 64 && calls == 4);
    EXPECT(fields.count(PLEAT_WRINKLE_FIELD_PHASE) == fine.vertex_count());
    EXPECT(fields.get(PLEAT_WRINKLE_FIELD_NORMALS).size() == 3 * fine.vertex_count());
    try {
        fields.get(PLEAT_WRINKLE_FIELD_Z);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
    }
    // cancelling, and an exception thrown by the callback comes back out
    try {
        cwf.evaluate(p, nullptr, nullptr, [](const char *, double) { return false; });
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_CANCELLED);
    }
    try {
        cwf.evaluate(p, nullptr, nullptr, [](const char *, double) -> bool {
            throw std::runtime_error("from the callback");
        });
        EXPECT(false);
    } catch (const pleat::Error &) {
        EXPECT(false);
    } catch (const std::runtime_error &err) {
        EXPECT(std::string(err.what()) == "from the callback");
    }
    // Knoppel's phase (zeta omitted), moves, and a size mistake
    pleat::Cwf knoppel = pleat::Cwf::from_edge_omega(base, omega, amp);
    pleat::Cwf moved = std::move(knoppel);
    EXPECT(!knoppel && moved && moved.zeta().size() == 8);
    try {
        omega.pop_back();
        pleat::Cwf::from_edge_omega(base, omega, amp, zeta);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: short omega -> %s\n", err.what());
    }
}

int main() {
    const double p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t t[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
    pleat::Mesh m = pleat::Mesh::from_arrays(p, 4, t, 12);
    EXPECT(m.vertex_count() == 4 && m.triangle_count() == 4);
    EXPECT(m.positions()[3] == 1.0 && m.indices()[1] == 2);
    pleat::Mesh moved = std::move(m);
    EXPECT(!m && moved);
    try {
        const double bad[] = {0, 0, 0, NAN, 0, 0, 0, 1, 0, 0, 0, 1};
        pleat::Mesh::from_arrays(bad, 4, t, 12);
        EXPECT(false);
    } catch (const pleat::Error &e) {
        EXPECT(e.status() == PLEAT_STATUS_INVALID_MESH);
        std::printf("  ok: NaN rejected -> %s\n", e.what());
    }
    try {
        pleat::Mesh::read("does/not/exist.obj");
        EXPECT(false);
    } catch (const pleat::Error &e) {
        EXPECT(e.status() == PLEAT_STATUS_IO);
        std::printf("  ok: missing file -> %s\n", e.what());
    }
    wrinkles(moved);
    std::printf("cpp_raii: %d passed, %d failed\n", checks - failures, failures);
    return failures == 0 ? 0 : 1;
}
