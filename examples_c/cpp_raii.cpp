// The C++ RAII wrapper: create, copy out, errors as exceptions, moves.
#include <cmath>
#include <cstdio>
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
    std::printf("cpp_raii: %d passed, %d failed\n", checks - failures, failures);
    return failures == 0 ? 0 : 1;
}
