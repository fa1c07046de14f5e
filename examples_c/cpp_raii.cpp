// The C++ RAII wrapper (bindings/cpp/pleat.hpp) over every capability of the C API: meshes,
// the validity report, LODs, LOD chains, cages, offset surfaces with stats, wrinkle fields and
// their interpolation; errors as exceptions, moves, progress and cancellation.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include <unistd.h>
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
    EXPECT(fine.triangle_count() == 4 * 64 && stats.triangle_count == 4 * 64 && calls == 3 * 6); // 6 progress calls per level
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
    // per-corner omega round trip, float copy into an interleaved buffer
    std::vector<double> corners = cwf.corner_omega();
    EXPECT(corners.size() == 12 && cwf.triangle_count() == 4);
    pleat::Cwf from_corners = pleat::Cwf::from_corner_omega(base, corners, amp, zeta);
    EXPECT(std::fabs(from_corners.omega()[5] - omega[5]) < 1e-14);
    std::vector<float> interleaved(4 * fine.vertex_count(), -1.0f);
    fields.copy(PLEAT_WRINKLE_FIELD_NORMALS, interleaved.data(), fine.vertex_count(), 16);
    EXPECT(interleaved[3] == -1.0f && std::fabs(interleaved[0]) <= 1.0f);

    // interpolation between two keyframes: frames, history, files
    std::vector<double> amp_b(base.vertex_count(), 0.1);
    pleat::Cwf key_b = pleat::Cwf::from_edge_omega(base, omega, amp_b, zeta);
    PleatWrinkleInterpParams ip = pleat_wrinkle_interp_params_default();
    ip.guide_frames = 2;
    ip.substeps = 2;
    ip.max_iterations = 20;
    PleatWrinkleInterpStats is{};
    is.struct_size = sizeof is;
    pleat::Animation anim = cwf.interpolate(key_b, ip, &is);
    EXPECT(anim.frame_count() == 5 && anim.guide_count() == 2);
    EXPECT(anim.history().size() == 2 * (is.iterations + 1));
    EXPECT(std::fabs(anim.frame(0.5).amplitude()[0] - 0.075) < 1e-12);
    EXPECT(anim.frame(1.0).amplitude() == amp_b);
    const char *tmp = std::getenv("TMPDIR");
    const std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/pleat_cpp_raii_" +
                             std::to_string(getpid()) + ".cwfa";
    anim.write(path);
    pleat::Animation back = pleat::Animation::read(base, path);
    std::remove(path.c_str());
    EXPECT(back.frame_count() == 5 && back.frame(0.25).zeta() == anim.frame(0.25).zeta());
    try {
        anim.frame(2.0);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
    }
    try {
        cwf.edit_report();  // not made by edit: no edit report
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
    }
    ip.locality = 0;  // every vertex solved
    EXPECT(cwf.interpolate(key_b, ip).frame_count() == 5);
    try {
        cwf.knoppel_report();  // zeta was given: no solve, no report
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
    }

    // Knoppel's phase (zeta omitted), moves, and a size mistake
    pleat::Cwf knoppel = pleat::Cwf::from_edge_omega(base, omega, amp);
    pleat::Cwf moved = std::move(knoppel);
    EXPECT(!knoppel && moved && moved.zeta().size() == 8);
    EXPECT(moved.knoppel_report().iterations >= 1);
    try {
        omega.pop_back();
        pleat::Cwf::from_edge_omega(base, omega, amp, zeta);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: short omega -> %s\n", err.what());
    }
}

// pleat::Mesh::lod / lod_chain / cage / offset on a unit cube, checked by the validity report.
static void lods() {
    const float p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    const uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    pleat::Mesh cube = pleat::Mesh::from_arrays(p, 8, t, 36);
    if (!pleat::has_feature("lod")) {
        try {
            cube.lod(10.0);
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_UNSUPPORTED);
        }
        return;
    }
    PleatLodStats stats = pleat::lod_stats();
    int calls = 0;
    pleat::Mesh lod = cube.lod(pleat::lod_params(10.0), &stats, [&](const char *, double f) {
        calls++;
        return f >= 0.0 && f <= 1.0;
    });
    PleatMeshReport r = lod.report();
    EXPECT(r.is_watertight && r.self_intersection_free && r.consistently_oriented);
    // the report with progress: the same bytes; cancelling throws CANCELLED
    int check_calls = 0;
    PleatMeshReport rp = lod.report(0, [&](const char *stage, double) {
        check_calls += std::string(stage) == "check";
        return true;
    });
    EXPECT(std::memcmp(&rp, &r, sizeof r) == 0 && check_calls >= 7);
    try {
        lod.report(0, [](const char *, double) { return false; });
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_CANCELLED);
    }
    EXPECT(stats.watertight && stats.face_count == lod.triangle_count() && calls > 0);
    // positions into an interleaved buffer (xyz + one float of padding per vertex)
    std::vector<float> interleaved(4 * lod.vertex_count(), 7.0f);
    lod.copy_positions(interleaved.data(), lod.vertex_count(), 16);
    EXPECT(interleaved[3] == 7.0f && interleaved[0] == lod.positions_f32()[0]);

    // pleat::Transfer: the cube's per-vertex UVs, ids and skin weights on the LOD
    {
        pleat::Transfer tr(cube, lod, pleat::transfer_params(10.0));
        std::vector<float> uv(16), w(16, 0.0f);
        std::vector<uint32_t> ids(8), joints(16);
        for (uint32_t v = 0; v < 8; v++) {
            uv[2 * v] = p[3 * v], uv[2 * v + 1] = p[3 * v + 1], ids[v] = 100 + v;
            joints[2 * v] = v % 2, joints[2 * v + 1] = 2, w[2 * v] = 0.75f, w[2 * v + 1] = 0.25f;
        }
        std::vector<float> luv = tr.f32(uv, 2);
        std::vector<uint32_t> lid = tr.u32(ids, 1);
        pleat::SkinWeights sw = tr.skin(joints, w, 2);
        EXPECT(luv.size() == 2 * lod.vertex_count() && lid.size() == lod.vertex_count());
        EXPECT(lid[0] >= 100 && lid[0] < 108 && luv[0] >= -1e-6f && luv[0] <= 1.0f + 1e-6f);
        EXPECT(sw.weights.size() == 4 * lod.vertex_count());
        EXPECT(std::fabs(sw.weights[0] + sw.weights[1] + sw.weights[2] + sw.weights[3] - 1.0f) <=
               1e-6f);
        pleat::Transfer moved_tr = std::move(tr);
        EXPECT(!tr.get() && moved_tr.lod_vertex_count() == lod.vertex_count());
        try {
            float big[24];
            for (int i = 0; i < 24; i++) big[i] = 3.0f * p[i];
            pleat::Mesh other = pleat::Mesh::from_arrays(big, 8, t, 36);
            tr = pleat::Transfer(other, lod, pleat::transfer_params(10.0));
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT && !tr.get());
            std::printf("  ok: not the LOD's input -> %s\n", err.what());
        }
        try {
            moved_tr.f32(std::vector<float>(15), 2);
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        }
    }

    // pleat::Deformation: the cube's two-joint skin followed by the LOD; a mismatched
    // array is refused before pleat is called
    {
        std::vector<uint32_t> joints(16);
        std::vector<float> w(16);
        for (uint32_t v = 0; v < 8; v++)
            joints[2 * v] = 0, joints[2 * v + 1] = 1, w[2 * v] = p[3 * v + 2], w[2 * v + 1] = 1 - p[3 * v + 2];
        pleat::Deformation skin(8, 2, joints, w, {0, 0, 0, 0, 0, 1});
        PleatLodParams dp = pleat::lod_params(10.0);
        dp.deformation = skin.get();
        pleat::Mesh followed = cube.lod(dp);
        EXPECT(followed.report().is_watertight);
        pleat::Deformation moved = std::move(skin);
        EXPECT(!skin.get() && moved.get());
        try {
            pleat::Deformation bad(8, 2, joints, std::vector<float>(15));
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        }
    }

    std::vector<PleatLodStats> chain_stats;
    std::vector<pleat::Mesh> chain = cube.lod_chain({10.0, 5.0}, pleat::lod_params(), &chain_stats);
    EXPECT(chain.size() == 2 && chain_stats.size() == 2 && chain[1].report().is_watertight);
    EXPECT(chain_stats[0].offset_distance < chain_stats[1].offset_distance);

    if (pleat::has_feature("cage")) {
        PleatLodStats cs = pleat::lod_stats();
        pleat::Mesh cage = cube.cage(pleat::lod_params(10.0), &cs);
        EXPECT(cs.encloses_input == 1 && cage.report().is_watertight);
    }

    PleatOffsetParams op = pleat_offset_params_default();
    op.screen_size = 10.0;
    pleat::Stats ostats;
    pleat::Mesh off = cube.offset(op, &ostats);
    EXPECT(off.report(PLEAT_CHECK_SKIP_SELF_INTERSECTIONS).is_watertight);
    EXPECT(ostats.count(PLEAT_STATS_KIND_STAGE) > 0 && ostats.total_seconds() > 0.0);
    EXPECT(ostats.value(PLEAT_STATS_KIND_VERIFIED, "watertight") == 1.0);
    EXPECT(ostats.json().find("\"verified\"") != std::string::npos);

    // cancel, an exception from the callback, and a bad parameter
    try {
        cube.lod(pleat::lod_params(10.0), nullptr, [](const char *, double) { return false; });
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_CANCELLED);
    }
    try {
        // lod, not cage: a lod-only build has no cage and would answer UNSUPPORTED first
        cube.lod(pleat::lod_params(10.0), nullptr, [](const char *, double) -> bool {
            throw std::runtime_error("from the callback");
        });
        EXPECT(false);
    } catch (const std::runtime_error &err) {
        EXPECT(std::string(err.what()) == "from the callback");
    }
    try {
        cube.lod(-1.0);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT && !pleat::last_error().empty());
        std::printf("  ok: negative screen size -> %s\n", err.what());
    }
}

// pleat::TfwScene / TfwResult: a 7 x 4 stretched sheet from arrays, solved briefly.
static void tension_field() {
    if (!pleat::has_feature("tfw")) {
        try {
            pleat::TfwScene::from_json("{}");
            EXPECT(false);
        } catch (const pleat::Error &err) {
            EXPECT(err.status() == PLEAT_STATUS_UNSUPPORTED);
        }
        return;
    }
    const int nx = 7, ny = 4;
    std::vector<double> rest, pos;
    std::vector<uint32_t> tris, clamped;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double u = 0.25 * i / (nx - 1), v = 0.1 * j / (ny - 1);
            rest.insert(rest.end(), {u, v});
            pos.insert(pos.end(), {(u - 0.125) * 1.05, v - 0.05, 0.0});
        }
    for (int j = 0; j + 1 < ny; j++)
        for (int i = 0; i + 1 < nx; i++) {
            uint32_t a = uint32_t(j * nx + i), b = a + 1, c = a + nx + 1, d = a + nx;
            tris.insert(tris.end(), {a, b, c, a, c, d});
        }
    for (int j = 0; j < ny; j++) clamped.insert(clamped.end(), {uint32_t(j * nx), uint32_t(j * nx + nx - 1)});
    pleat::TfwScene scene = pleat::TfwScene::from_arrays(rest, tris, pos, clamped);
    PleatTfwParams params = pleat::tfw_params();
    params.sqp_max_iterations = 5;
    pleat::TfwResult result = scene.solve(params);
    PleatTfwStats st = result.stats();
    const size_t nv = size_t(nx * ny);
    EXPECT(st.vertex_count == nv && st.sqp_iterations <= 5);
    EXPECT(result.history().size() == PLEAT_TFW_HISTORY_COLUMNS * st.sqp_iterations);
    EXPECT(result.base_mesh().vertex_count() == nv);
    EXPECT(result.cwf().vertex_count() == nv);
    EXPECT(result.evaluate(1).triangle_count() == 4 * st.triangle_count);
    PleatTfwWaveCount waves = result.count_waves(2);
    EXPECT(waves.samples > 0 && waves.waves >= 0.0);
    PleatTfwObstacle plane = pleat_tfw_obstacle_default();
    plane.point[2] = -0.01;
    scene.add_obstacle(plane);
    PleatTfwObstacle ball = pleat_tfw_obstacle_default();
    ball.kind = PLEAT_TFW_OBSTACLE_SPHERE; // radius left at 0: rejected
    try {
        scene.add_obstacle(ball);
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: sphere without radius -> %s\n", err.what());
    }
    try {
        scene.solve(params, [](const char *, double) { return false; });
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_CANCELLED);
    }
    try {
        pleat::TfwScene::from_json("{\"material\": {\"yung\": 1}}");
        EXPECT(false);
    } catch (const pleat::Error &err) {
        EXPECT(err.status() == PLEAT_STATUS_INVALID_ARGUMENT);
        std::printf("  ok: unknown scene key -> %s\n", err.what());
    }
}

int main() {
    EXPECT(pleat::abi_version() == PLEAT_ABI_VERSION && !pleat::version().empty());
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
    EXPECT(moved.report().is_watertight && moved.report().total_genus == 0);
    wrinkles(moved);
    lods();
    tension_field();
    std::printf("cpp_raii: %d passed, %d failed\n", checks - failures, failures);
    return failures == 0 ? 0 : 1;
}
