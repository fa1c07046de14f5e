// pleat.hpp — header-only C++17 RAII wrappers over the C API in pleat.h.
//
// Every failing call throws pleat::Error carrying the PleatStatus and pleat's message.
// Handles are move-only and released in destructors.
#ifndef PLEAT_HPP
#define PLEAT_HPP

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pleat.h"

namespace pleat {

/// Thrown by every wrapper whose C call returned a status other than PLEAT_STATUS_OK.
class Error : public std::runtime_error {
  public:
    Error(PleatStatus status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    /// The C status code.
    PleatStatus status() const noexcept { return status_; }

  private:
    PleatStatus status_;
};

/// Throws pleat::Error when `s` is not PLEAT_STATUS_OK.
inline void check(PleatStatus s) {
    if (s != PLEAT_STATUS_OK) throw Error(s, pleat_last_error());
}

/// Library version string.
inline std::string version() { return pleat_version(); }

/// Sets pleat's worker thread count (0 = all cores).
inline void set_thread_count(uint32_t n) { check(pleat_set_thread_count(n)); }

/// An owned, immutable triangle mesh (wraps PleatMesh*).
class Mesh {
  public:
    Mesh() = default;
    /// Takes ownership of a handle returned by the C API.
    explicit Mesh(PleatMesh *raw) noexcept : raw_(raw) {}
    Mesh(const Mesh &) = delete;
    Mesh &operator=(const Mesh &) = delete;
    Mesh(Mesh &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Mesh &operator=(Mesh &&o) noexcept {
        if (this != &o) {
            pleat_mesh_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Mesh() { pleat_mesh_destroy(raw_); }

    /// From xyz float triples (`stride_bytes` apart, 0 = packed) and triangle indices.
    static Mesh from_arrays(const float *positions, size_t vertex_count, const uint32_t *indices,
                            size_t index_count, size_t stride_bytes = 0) {
        PleatMesh *m = nullptr;
        check(pleat_mesh_create_f32(positions, vertex_count, stride_bytes, indices, index_count, &m));
        return Mesh(m);
    }
    /// From xyz double triples and triangle indices.
    static Mesh from_arrays(const double *positions, size_t vertex_count, const uint32_t *indices,
                            size_t index_count, size_t stride_bytes = 0) {
        PleatMesh *m = nullptr;
        check(pleat_mesh_create_f64(positions, vertex_count, stride_bytes, indices, index_count, &m));
        return Mesh(m);
    }
    /// Reads a mesh file (obj, ply, off, stl, glb, gltf).
    static Mesh read(const std::string &path) {
        PleatMesh *m = nullptr;
        check(pleat_mesh_read_file(path.c_str(), &m));
        return Mesh(m);
    }
    /// Writes a mesh file; format by extension.
    void write(const std::string &path) const { check(pleat_mesh_write_file(raw_, path.c_str())); }

    size_t vertex_count() const noexcept { return pleat_mesh_vertex_count(raw_); }
    size_t triangle_count() const noexcept { return pleat_mesh_triangle_count(raw_); }

    /// Positions as packed xyz doubles.
    std::vector<double> positions() const {
        std::vector<double> p(3 * vertex_count());
        check(pleat_mesh_copy_positions_f64(raw_, p.data(), vertex_count(), 0));
        return p;
    }
    /// Triangle indices, three per triangle.
    std::vector<uint32_t> indices() const {
        std::vector<uint32_t> i(3 * triangle_count());
        check(pleat_mesh_copy_indices(raw_, i.data(), i.size()));
        return i;
    }

    /// The underlying handle (still owned by this object).
    const PleatMesh *get() const noexcept { return raw_; }
    /// Gives up ownership of the handle.
    PleatMesh *release() noexcept { return std::exchange(raw_, nullptr); }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatMesh *raw_ = nullptr;
};

}  // namespace pleat

#endif  // PLEAT_HPP
