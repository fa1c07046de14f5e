// pleat.hpp — header-only C++17 RAII wrappers over the C API in pleat.h.
//
// Every failing call throws pleat::Error carrying the PleatStatus and pleat's message.
// Handles are move-only and released in destructors.
#ifndef PLEAT_HPP
#define PLEAT_HPP

#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
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

    /// Number of unique edges (the length of per-edge data such as wrinkle omega).
    size_t edge_count() const noexcept { return pleat_mesh_edge_count(raw_); }
    /// Edges in pleat's numbering, two indices per edge (a < b, sorted by (a, b)).
    std::vector<uint32_t> edges() const {
        size_t n = edge_count();
        std::vector<uint32_t> e(2 * n + 1);
        check(pleat_mesh_copy_edges(raw_, e.data(), n));
        e.resize(2 * n);
        return e;
    }

    /// The underlying handle (still owned by this object).
    const PleatMesh *get() const noexcept { return raw_; }
    /// Gives up ownership of the handle.
    PleatMesh *release() noexcept { return std::exchange(raw_, nullptr); }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatMesh *raw_ = nullptr;
};

/// Per-vertex (and per-edge) fields of one wrinkle evaluation (wraps PleatWrinkleFields*).
class WrinkleFields {
  public:
    WrinkleFields() = default;
    explicit WrinkleFields(PleatWrinkleFields *raw) noexcept : raw_(raw) {}
    WrinkleFields(const WrinkleFields &) = delete;
    WrinkleFields &operator=(const WrinkleFields &) = delete;
    WrinkleFields(WrinkleFields &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    WrinkleFields &operator=(WrinkleFields &&o) noexcept {
        if (this != &o) {
            pleat_wrinkle_fields_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~WrinkleFields() { pleat_wrinkle_fields_destroy(raw_); }

    /// Elements of `field` (a PLEAT_WRINKLE_FIELD_* value); 0 when it was not requested.
    size_t count(uint32_t field) const noexcept { return pleat_wrinkle_fields_count(raw_, field); }
    /// The field as packed doubles (1, 2 or 3 per element, see PLEAT_WRINKLE_FIELD_*).
    std::vector<double> get(uint32_t field) const {
        size_t n = count(field);
        std::vector<double> v(3 * n + 1);
        check(pleat_wrinkle_fields_copy(raw_, field, v.data(), n, 0));
        size_t comps = field == PLEAT_WRINKLE_FIELD_Z ? 2
                       : (field == PLEAT_WRINKLE_FIELD_NORMALS ||
                          field == PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS)
                           ? 3
                           : 1;
        v.resize(comps * n);
        return v;
    }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatWrinkleFields *raw_ = nullptr;
};

/// A complex wrinkle field on a base mesh (wraps PleatCwf*): omega per edge of
/// `base.edges()`, amplitude and unit phase zeta (re, im) per vertex. Needs the "wrinkle"
/// capability (else pleat::Error with PLEAT_STATUS_UNSUPPORTED).
class Cwf {
  public:
    Cwf() = default;
    explicit Cwf(PleatCwf *raw) noexcept : raw_(raw) {}
    Cwf(const Cwf &) = delete;
    Cwf &operator=(const Cwf &) = delete;
    Cwf(Cwf &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Cwf &operator=(Cwf &&o) noexcept {
        if (this != &o) {
            pleat_cwf_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Cwf() { pleat_cwf_destroy(raw_); }

    /// From omega per edge, amplitude per vertex and zeta (2 doubles per vertex; empty =
    /// Knoppel's phase computed from omega). Sizes are checked by pleat.
    static Cwf from_edge_omega(const Mesh &base, const std::vector<double> &omega,
                               const std::vector<double> &amplitude,
                               const std::vector<double> &zeta_re_im = {}) {
        PleatCwf *c = nullptr;
        check_zeta(zeta_re_im, amplitude.size());
        check(pleat_cwf_create(base.get(), omega.data(), omega.size(), amplitude.data(),
                               zeta_re_im.empty() ? nullptr : zeta_re_im.data(),
                               amplitude.size(), &c));
        return Cwf(c);
    }
    /// From omega per triangle corner (3 per triangle, corner i to i+1; antisymmetric across
    /// shared edges), otherwise as from_edge_omega.
    static Cwf from_corner_omega(const Mesh &base, const std::vector<double> &corner_omega,
                                 const std::vector<double> &amplitude,
                                 const std::vector<double> &zeta_re_im = {}) {
        PleatCwf *c = nullptr;
        check_zeta(zeta_re_im, amplitude.size());
        check(pleat_cwf_create_from_corner_omega(
            base.get(), corner_omega.data(), corner_omega.size(), amplitude.data(),
            zeta_re_im.empty() ? nullptr : zeta_re_im.data(), amplitude.size(), &c));
        return Cwf(c);
    }
    /// From wave vectors (3 doubles each, per vertex or per face) with Knoppel's phase.
    static Cwf from_frequency(const Mesh &base, const std::vector<double> &vectors,
                              const std::vector<double> &amplitude,
                              uint32_t location = PLEAT_FREQUENCY_PER_VERTEX,
                              const PleatKnoppelParams *params = nullptr) {
        PleatCwf *c = nullptr;
        if (vectors.size() % 3 != 0)
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT, "vectors: 3 doubles per vector");
        check(pleat_cwf_create_from_frequency(base.get(), vectors.data(), vectors.size() / 3,
                                              location, amplitude.data(), amplitude.size(),
                                              params, &c));
        return Cwf(c);
    }
    /// Reads a .cwf file written for `base`.
    static Cwf read(const Mesh &base, const std::string &path) {
        PleatCwf *c = nullptr;
        check(pleat_cwf_read_file(base.get(), path.c_str(), &c));
        return Cwf(c);
    }
    /// Writes the .cwf file (lossless).
    void write(const std::string &path) const { check(pleat_cwf_write_file(raw_, path.c_str())); }

    size_t vertex_count() const noexcept { return pleat_cwf_vertex_count(raw_); }
    size_t edge_count() const noexcept { return pleat_cwf_edge_count(raw_); }

    std::vector<double> omega() const {
        std::vector<double> v(edge_count() + 1);
        check(pleat_cwf_copy_omega(raw_, v.data(), edge_count()));
        v.pop_back();
        return v;
    }
    std::vector<double> amplitude() const {
        std::vector<double> v(vertex_count() + 1);
        check(pleat_cwf_copy_amplitude(raw_, v.data(), vertex_count()));
        v.pop_back();
        return v;
    }
    /// zeta as (re, im) pairs.
    std::vector<double> zeta() const {
        std::vector<double> v(2 * vertex_count() + 1);
        check(pleat_cwf_copy_zeta(raw_, v.data(), vertex_count()));
        v.pop_back();
        return v;
    }

    /// The wrinkled mesh after `levels` Loop refinements (other parameters at their defaults).
    Mesh evaluate(uint32_t levels = 3) const {
        PleatWrinkleEvalParams p = pleat_wrinkle_eval_params_default();
        p.levels = levels;
        return evaluate(p);
    }
    /// The wrinkled mesh; fields requested in `params.flags` go to `*fields` when non-null.
    /// `keep_going(stage, fraction)` is called after each level; return false to cancel
    /// (pleat::Error with PLEAT_STATUS_CANCELLED). An exception it throws is rethrown here.
    Mesh evaluate(const PleatWrinkleEvalParams &params, WrinkleFields *fields = nullptr,
                  PleatWrinkleEvalStats *stats = nullptr,
                  const std::function<bool(const char *, double)> &keep_going = {}) const {
        struct Relay {
            const std::function<bool(const char *, double)> *fn;
            std::exception_ptr error;
        } relay{&keep_going, nullptr};
        PleatProgressFn cb = nullptr;
        if (keep_going)
            cb = [](void *user, const PleatProgress *info) -> int32_t {
                Relay *r = static_cast<Relay *>(user);
                try {
                    return (*r->fn)(info->stage, info->fraction) ? 0 : 1;
                } catch (...) {
                    r->error = std::current_exception();
                    return 1;
                }
            };
        PleatMesh *m = nullptr;
        PleatWrinkleFields *f = nullptr;
        PleatStatus s = pleat_cwf_evaluate(raw_, &params, cb, &relay, &m, fields ? &f : nullptr,
                                           stats);
        if (relay.error) std::rethrow_exception(relay.error);
        check(s);
        if (fields) *fields = WrinkleFields(f);
        return Mesh(m);
    }

    const PleatCwf *get() const noexcept { return raw_; }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    static void check_zeta(const std::vector<double> &zeta, size_t vertex_count) {
        if (!zeta.empty() && zeta.size() != 2 * vertex_count)
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT,
                        "zeta_re_im: 2 doubles per vertex (or empty for Knoppel's phase)");
    }
    PleatCwf *raw_ = nullptr;
};

}  // namespace pleat

#endif  // PLEAT_HPP
