// pleat.hpp — header-only C++17 RAII wrappers over the C API in pleat.h.
//
// Covers the whole C API: meshes (arrays, files, validity report), LODs, LOD chains, cages,
// offset surfaces with their stats, attribute transfer to LODs (Transfer), wrinkle fields (creation, copy-out, Knoppel report,
// evaluation with fields), wrinkle animations (interpolation, frames, history, files) and
// tension-field wrinkles (TfwScene, TfwResult).
// Every failing call throws pleat::Error carrying the PleatStatus and pleat's message.
// Handles are move-only and released in destructors. Progress callbacks return false to
// cancel; an exception thrown by one comes out of the call that ran it.
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

/// Library version string (`major.minor.patch`, Cargo.toml's).
inline std::string version() { return pleat_version(); }

/// The C ABI version of the loaded library; compare with PLEAT_ABI_VERSION.
inline uint32_t abi_version() noexcept { return pleat_abi_version(); }

/// True when the library was built with capability `name` ("lod", "cage", "wrinkle", ...).
inline bool has_feature(const char *name) noexcept { return pleat_has_feature(name) != 0; }

/// The message of the last failed pleat call on this thread ("" after a success).
inline std::string last_error() { return pleat_last_error(); }

/// Sets pleat's worker thread count (0 = all cores).
inline void set_thread_count(uint32_t n) { check(pleat_set_thread_count(n)); }

/// Worker threads the next call will use (>= 1).
inline uint32_t thread_count() noexcept { return pleat_thread_count(); }

/// Progress callback of long operations: called on the calling thread with the stage name and
/// the fraction done; return false to cancel (the call then throws pleat::Error with
/// PLEAT_STATUS_CANCELLED). An exception it throws cancels the call and is rethrown from it.
using Progress = std::function<bool(const char *stage, double fraction)>;

namespace detail {
/// Adapts a pleat::Progress to PleatProgressFn + user_data and carries its exception out.
class ProgressRelay {
  public:
    explicit ProgressRelay(const Progress &fn) : fn_(&fn) {}
    PleatProgressFn callback() const noexcept { return *fn_ ? &ProgressRelay::call : nullptr; }
    void *user_data() noexcept { return this; }
    /// Rethrows the callback's exception, else throws pleat::Error for a failing status.
    void finish(PleatStatus s) const {
        if (error_) std::rethrow_exception(error_);
        check(s);
    }

  private:
    static int32_t call(void *user, const PleatProgress *info) {
        auto *self = static_cast<ProgressRelay *>(user);
        try {
            return (*self->fn_)(info->stage, info->fraction) ? 0 : 1;
        } catch (...) {
            self->error_ = std::current_exception();
            return 1;
        }
    }
    const Progress *fn_;
    std::exception_ptr error_;
};
}  // namespace detail

/// Default LOD/cage parameters (the dissertation's) with `screen_size` set.
inline PleatLodParams lod_params(double screen_size = 200.0) noexcept {
    PleatLodParams p = pleat_lod_params_default();
    p.screen_size = screen_size;
    return p;
}

/// A PleatLodStats ready to be filled (`struct_size` set).
inline PleatLodStats lod_stats() noexcept {
    PleatLodStats s{};
    s.struct_size = sizeof s;
    return s;
}

/// Statistics of one long operation (wraps PleatStats*): per-stage seconds, counts, metrics
/// and verified guarantees, by kind and index or as JSON.
class Stats {
  public:
    Stats() = default;
    explicit Stats(PleatStats *raw) noexcept : raw_(raw) {}
    Stats(const Stats &) = delete;
    Stats &operator=(const Stats &) = delete;
    Stats(Stats &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Stats &operator=(Stats &&o) noexcept {
        if (this != &o) {
            pleat_stats_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Stats() { pleat_stats_destroy(raw_); }

    /// Number of entries of `kind` (PLEAT_STATS_KIND_*).
    size_t count(PleatStatsKind kind) const noexcept { return pleat_stats_count(raw_, kind); }
    /// Entry `index` of `kind`: (name, value); seconds, a count, a metric or 1/0.
    std::pair<std::string, double> entry(PleatStatsKind kind, size_t index) const {
        const char *name = nullptr;
        double value = 0.0;
        check(pleat_stats_entry(raw_, kind, index, &name, &value));
        return {name, value};
    }
    /// The value of the entry of `kind` called `name`; throws INVALID_ARGUMENT when absent.
    double value(PleatStatsKind kind, const std::string &name) const {
        for (size_t i = 0; i < count(kind); i++) {
            auto e = entry(kind, i);
            if (e.first == name) return e.second;
        }
        throw Error(PLEAT_STATUS_INVALID_ARGUMENT, "no stats entry named " + name);
    }
    /// Total wall-clock seconds over all stages.
    double total_seconds() const noexcept { return pleat_stats_total_seconds(raw_); }
    /// The stats as one JSON object ({"stages":…,"counts":…,"metrics":…,"verified":…}).
    std::string json() const {
        size_t needed = 0;
        check(pleat_stats_to_json(raw_, nullptr, 0, &needed));
        std::string s(needed + 1, '\0');
        check(pleat_stats_to_json(raw_, &s[0], s.size(), nullptr));
        s.resize(needed);
        return s;
    }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatStats *raw_ = nullptr;
};

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

    /// Positions as packed xyz floats (rounded to nearest).
    std::vector<float> positions_f32() const {
        std::vector<float> p(3 * vertex_count() + 3);
        check(pleat_mesh_copy_positions_f32(raw_, p.data(), vertex_count(), 0));
        p.resize(3 * vertex_count());
        return p;
    }
    /// Copies the positions into a caller's (possibly interleaved) vertex buffer: xyz floats
    /// every `stride_bytes` (0 = packed); bytes in between are left untouched.
    void copy_positions(float *dst, size_t vertex_capacity, size_t stride_bytes = 0) const {
        check(pleat_mesh_copy_positions_f32(raw_, dst, vertex_capacity, stride_bytes));
    }
    /// As copy_positions with doubles.
    void copy_positions(double *dst, size_t vertex_capacity, size_t stride_bytes = 0) const {
        check(pleat_mesh_copy_positions_f64(raw_, dst, vertex_capacity, stride_bytes));
    }

    /// Validity report, pleat_mesh_check (PLEAT_CHECK_* flags: skip self-intersections,
    /// weld first); with a `progress` callback, pleat_mesh_check_with_progress (stage
    /// "check"; returning false cancels).
    PleatMeshReport report(uint32_t flags = 0, const Progress &progress = {}) const {
        PleatMeshReport r{};
        r.struct_size = sizeof r;
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_mesh_check_with_progress(raw_, flags, relay.callback(),
                                                    relay.user_data(), &r));
        return r;
    }

    /// One LOD for `params.screen_size` pixels (see pleat::lod_params); fills `*stats` when
    /// non-null. Watertight, manifold, self-intersection-free.
    Mesh lod(const PleatLodParams &params, PleatLodStats *stats = nullptr,
             const Progress &progress = {}) const {
        return bake(&pleat_lod_generate, params, stats, progress);
    }
    /// One LOD for `screen_size` pixels with the default parameters.
    Mesh lod(double screen_size) const { return lod(lod_params(screen_size)); }
    /// A cage: like lod, but enclosing this mesh without touching it
    /// (`stats->encloses_input` is the verification).
    Mesh cage(const PleatLodParams &params, PleatLodStats *stats = nullptr,
              const Progress &progress = {}) const {
        return bake(&pleat_cage_generate, params, stats, progress);
    }
    /// One LOD per screen size, in the order given; coarser levels start from finer results.
    /// `params.screen_size`/`target_faces` are ignored; `*stats` is resized and filled.
    std::vector<Mesh> lod_chain(const std::vector<double> &screen_sizes,
                                const PleatLodParams &params = lod_params(),
                                std::vector<PleatLodStats> *stats = nullptr,
                                const Progress &progress = {}) const {
        std::vector<PleatMesh *> raw(screen_sizes.size() + 1, nullptr);
        if (stats) stats->assign(screen_sizes.size() + 1, lod_stats());
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_lod_generate_chain(raw_, screen_sizes.data(), screen_sizes.size(),
                                              &params, relay.callback(), relay.user_data(),
                                              raw.data(), stats ? stats->data() : nullptr));
        if (stats) stats->pop_back();
        std::vector<Mesh> out;
        out.reserve(screen_sizes.size());
        for (size_t i = 0; i < screen_sizes.size(); i++) out.emplace_back(raw[i]);
        return out;
    }
    /// The d-offset surface (LOD stage 1); `*stats` receives its PleatStats when non-null.
    Mesh offset(const PleatOffsetParams &params = pleat_offset_params_default(),
                Stats *stats = nullptr, const Progress &progress = {}) const {
        PleatMesh *m = nullptr;
        PleatStats *st = nullptr;
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_offset_surface(raw_, &params, relay.callback(), relay.user_data(), &m,
                                          stats ? &st : nullptr));
        if (stats) *stats = Stats(st);
        return Mesh(m);
    }

    /// The underlying handle (still owned by this object).
    const PleatMesh *get() const noexcept { return raw_; }
    /// Gives up ownership of the handle.
    PleatMesh *release() noexcept { return std::exchange(raw_, nullptr); }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    using BakeFn = PleatStatus (*)(const PleatMesh *, const PleatLodParams *, PleatProgressFn,
                                   void *, PleatMesh **, PleatLodStats *);
    Mesh bake(BakeFn fn, const PleatLodParams &params, PleatLodStats *stats,
              const Progress &progress) const {
        PleatMesh *m = nullptr;
        PleatLodStats local = lod_stats();
        detail::ProgressRelay relay(progress);
        relay.finish(fn(raw_, &params, relay.callback(), relay.user_data(), &m,
                        stats ? stats : &local));
        return Mesh(m);
    }
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
    /// Copies the field as floats into a caller buffer, one element every `stride_bytes`
    /// (0 = packed), e.g. straight into an interleaved vertex buffer.
    void copy(uint32_t field, float *dst, size_t element_capacity, size_t stride_bytes = 0) const {
        check(pleat_wrinkle_fields_copy_f32(raw_, field, dst, element_capacity, stride_bytes));
    }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatWrinkleFields *raw_ = nullptr;
};

class Animation;

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
    /// A keyframe designed from wrinkle sources (dissertation 3.6.1;
    /// `pleat_cwf_design_with_progress`, stage "design"; `progress` returning false cancels).
    static Cwf design(const Mesh &base, const std::vector<PleatWrinkleSource> &sources,
                      const PleatCwfDesignParams *params = nullptr,
                      const PleatKnoppelParams *knoppel = nullptr,
                      const Progress &progress = {}) {
        PleatCwf *c = nullptr;
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_cwf_design_with_progress(base.get(), sources.data(), sources.size(),
                                                    params, knoppel, relay.callback(),
                                                    relay.user_data(), &c));
        return Cwf(c);
    }
    /// This keyframe with `regions` edited (dissertation 3.6.2;
    /// `pleat_cwf_edit_with_progress`, stage "edit"; `progress` returning false cancels); each
    /// region's `struct_size` must be `sizeof(PleatCwfRegionEdit)`. `labels`, when given,
    /// receives PLEAT_FACE_* per triangle.
    Cwf edit(const std::vector<PleatCwfRegionEdit> &regions,
             const PleatCwfEditParams *params = nullptr,
             std::vector<uint8_t> *labels = nullptr, const Progress &progress = {}) const {
        PleatCwf *c = nullptr;
        std::vector<uint8_t> l(triangle_count() + 1);
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_cwf_edit_with_progress(raw_, regions.data(), regions.size(), params,
                                                  relay.callback(), relay.user_data(), &c,
                                                  l.data()));
        l.pop_back();
        if (labels) *labels = std::move(l);
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
    size_t triangle_count() const noexcept { return pleat_cwf_triangle_count(raw_); }
    /// omega per triangle corner (3 per triangle, corner i to i+1).
    std::vector<double> corner_omega() const {
        std::vector<double> v(3 * triangle_count() + 1);
        check(pleat_cwf_copy_corner_omega(raw_, v.data(), 3 * triangle_count()));
        v.pop_back();
        return v;
    }
    /// Report of the Knoppel phase solve; INVALID_ARGUMENT when zeta was given, not solved.
    PleatKnoppelReport knoppel_report() const {
        PleatKnoppelReport r{};
        r.struct_size = sizeof r;
        check(pleat_cwf_get_knoppel_report(raw_, &r));
        return r;
    }
    /// What the `edit` that made this keyframe did (class sizes, residuals, the compatibility
    /// RMS by class, attempts of the adaptive width `PleatCwfEditParams::compat_target`);
    /// INVALID_ARGUMENT when this keyframe was not made by `edit`.
    PleatCwfEditReport edit_report() const {
        PleatCwfEditReport r{};
        r.struct_size = sizeof r;
        check(pleat_cwf_get_edit_report(raw_, &r));
        return r;
    }
    /// The interface width (rings) `edit` used per region, in the order of its `regions`
    /// (wider than requested when `compat_target` widened them).
    std::vector<uint32_t> edit_interface_rings() const {
        std::vector<uint32_t> v(edit_report().region_count + 1);
        check(pleat_cwf_copy_edit_interface_rings(raw_, v.data(), v.size()));
        v.pop_back();
        return v;
    }
    /// The animation from this keyframe (t = 0) to `other` (t = 1) on the same base mesh;
    /// `params.locality` (default 1) holds an edit's unchanged vertices at their keyframe phase.
    Animation interpolate(
        const Cwf &other,
        const PleatWrinkleInterpParams &params = pleat_wrinkle_interp_params_default(),
        PleatWrinkleInterpStats *stats = nullptr, const Progress &progress = {}) const;

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
                  const Progress &keep_going = {}) const {
        detail::ProgressRelay relay(keep_going);
        PleatMesh *m = nullptr;
        PleatWrinkleFields *f = nullptr;
        relay.finish(pleat_cwf_evaluate(raw_, &params, relay.callback(), relay.user_data(), &m,
                                        fields ? &f : nullptr, stats));
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

/// A wrinkle animation between two keyframes (wraps PleatCwfAnimation*): the field at any
/// t in [0, 1]. Made by Cwf::interpolate or Animation::read.
class Animation {
  public:
    Animation() = default;
    explicit Animation(PleatCwfAnimation *raw) noexcept : raw_(raw) {}
    Animation(const Animation &) = delete;
    Animation &operator=(const Animation &) = delete;
    Animation(Animation &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Animation &operator=(Animation &&o) noexcept {
        if (this != &o) {
            pleat_cwf_animation_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Animation() { pleat_cwf_animation_destroy(raw_); }

    /// Reads a .cwfa file written for `base`.
    static Animation read(const Mesh &base, const std::string &path) {
        PleatCwfAnimation *a = nullptr;
        check(pleat_cwf_animation_read_file(base.get(), path.c_str(), &a));
        return Animation(a);
    }
    /// Writes the .cwfa file (lossless).
    void write(const std::string &path) const {
        check(pleat_cwf_animation_write_file(raw_, path.c_str()));
    }
    /// Playback frames (guide_frames * substeps + 1); frame i is at t = i / (count - 1).
    size_t frame_count() const noexcept { return pleat_cwf_animation_frame_count(raw_); }
    /// Guide intervals N'.
    size_t guide_count() const noexcept { return pleat_cwf_animation_guide_count(raw_); }
    /// The field at time t in [0, 1] (0 and 1 reproduce the keyframes exactly).
    Cwf frame(double t) const {
        PleatCwf *c = nullptr;
        check(pleat_cwf_animation_frame(raw_, t, &c));
        return Cwf(c);
    }
    /// Convergence history: (seconds, normalized gradient norm) pairs, flattened.
    std::vector<double> history() const {
        size_t n = pleat_cwf_animation_history_count(raw_);
        std::vector<double> v(2 * n + 1);
        check(pleat_cwf_animation_copy_history(raw_, v.data(), n));
        v.resize(2 * n);
        return v;
    }
    const PleatCwfAnimation *get() const noexcept { return raw_; }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatCwfAnimation *raw_ = nullptr;
};

inline Animation Cwf::interpolate(const Cwf &other, const PleatWrinkleInterpParams &params,
                                  PleatWrinkleInterpStats *stats,
                                  const Progress &progress) const {
    PleatCwfAnimation *a = nullptr;
    detail::ProgressRelay relay(progress);
    relay.finish(pleat_cwf_interpolate(raw_, other.raw_, &params, relay.callback(),
                                       relay.user_data(), &a, stats));
    return Animation(a);
}

/// Where LOD points come from on the input (`lod_provenance`, `points_provenance`): per point,
/// the input triangle, barycentric coordinates (3 per point) and whether the cast along the
/// normal found it (else the closest point).
struct Provenance {
    std::vector<uint32_t> triangle;
    std::vector<double> bary;
    std::vector<uint8_t> by_ray;
};

/// Provenance of every vertex of `lod` on `input` (pleat_lod_provenance).
inline Provenance lod_provenance(const Mesh &lod, const Mesh &input,
                                 const PleatProvenanceParams &params =
                                     pleat_provenance_params_default()) {
    size_t n = lod.vertex_count();
    Provenance p{std::vector<uint32_t>(n), std::vector<double>(3 * n), std::vector<uint8_t>(n)};
    check(pleat_lod_provenance(lod.get(), input.get(), &params, p.triangle.data(), n,
                               p.bary.data(), 3 * n, p.by_ray.data(), n));
    return p;
}

/// Provenance of `points` (xyz triples) cast along `normals` (xyz triples, or empty for the
/// closest points) on `input` (pleat_points_provenance).
inline Provenance points_provenance(const Mesh &input, const std::vector<double> &points,
                                    const std::vector<double> &normals = {},
                                    const PleatProvenanceParams &params =
                                        pleat_provenance_params_default()) {
    size_t n = points.size() / 3;
    if (!normals.empty() && normals.size() != points.size())
        throw Error(PLEAT_STATUS_INVALID_ARGUMENT, "normals: one xyz per point needed");
    Provenance p{std::vector<uint32_t>(n), std::vector<double>(3 * n), std::vector<uint8_t>(n)};
    check(pleat_points_provenance(input.get(), points.data(),
                                  normals.empty() ? nullptr : normals.data(), n, &params,
                                  p.triangle.data(), n, p.bary.data(), 3 * n, p.by_ray.data(),
                                  n));
    return p;
}

/// Default transfer parameters with `screen_size` (the LOD's n_p) set.
inline PleatTransferParams transfer_params(double screen_size = 200.0) noexcept {
    PleatTransferParams p = pleat_transfer_params_default();
    p.screen_size = screen_size;
    return p;
}

/// Skin influences on a LOD's vertices (`Transfer::skin`): `influences` slots per vertex,
/// sorted by weight descending, each vertex's weights summing to 1 within 1e-6.
struct SkinWeights {
    size_t influences = 0;
    std::vector<uint32_t> joints;
    std::vector<float> weights;
};

/// The correspondence of a LOD's vertices on the input it was made from (wraps
/// PleatTransfer*), computed once and applied to any number of per-vertex arrays of the
/// input. Move-only. Construction throws pleat::Error (PLEAT_STATUS_INVALID_ARGUMENT) when
/// `input` is not the mesh `lod` was made from at `params.screen_size`.
class Transfer {
  public:
    Transfer() = default;
    Transfer(const Mesh &input, const Mesh &lod,
             const PleatTransferParams &params = pleat_transfer_params_default()) {
        check(pleat_transfer_create(input.get(), lod.get(), &params, &raw_));
    }
    Transfer(const Transfer &) = delete;
    Transfer &operator=(const Transfer &) = delete;
    Transfer(Transfer &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Transfer &operator=(Transfer &&o) noexcept {
        if (this != &o) {
            pleat_transfer_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Transfer() { pleat_transfer_destroy(raw_); }

    size_t lod_vertex_count() const noexcept { return pleat_transfer_lod_vertex_count(raw_); }
    size_t input_vertex_count() const noexcept {
        return pleat_transfer_input_vertex_count(raw_);
    }

    /// `values` (input vertex count × k) on the LOD's vertices (LOD vertex count × k), by
    /// `mode` (PLEAT_TRANSFER_BARYCENTRIC or PLEAT_TRANSFER_NEAREST).
    std::vector<float> f32(const std::vector<float> &values, size_t k,
                           uint32_t mode = PLEAT_TRANSFER_BARYCENTRIC) const {
        std::vector<float> out(k * lod_vertex_count());
        check(pleat_transfer_f32(raw_, mode, values.data(), rows(values.size(), k), k,
                                 out.data(), lod_vertex_count()));
        return out;
    }
    /// Integer attributes (ids, flags): the nearest corner's row.
    std::vector<uint32_t> u32(const std::vector<uint32_t> &values, size_t k) const {
        std::vector<uint32_t> out(k * lod_vertex_count());
        check(pleat_transfer_u32(raw_, values.data(), rows(values.size(), k), k, out.data(),
                                 lod_vertex_count()));
        return out;
    }
    /// Skin weights (input vertex count × m joints and weights) on the LOD's vertices, at
    /// most `max_influences` per vertex.
    SkinWeights skin(const std::vector<uint32_t> &joints, const std::vector<float> &weights,
                     size_t m, uint32_t max_influences = 4) const {
        if (joints.size() != weights.size())
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT, "joints and weights differ in length");
        size_t n = lod_vertex_count();
        SkinWeights s{max_influences, std::vector<uint32_t>(max_influences * n),
                      std::vector<float>(max_influences * n)};
        check(pleat_transfer_skin(raw_, joints.data(), weights.data(), rows(joints.size(), m),
                                  m, max_influences, s.joints.data(), s.weights.data(), n));
        return s;
    }

    PleatTransfer *get() const noexcept { return raw_; }

  private:
    /// Rows of an array of `size` values with `k` per row (a size that is not a multiple
    /// gives a count pleat refuses).
    static size_t rows(size_t size, size_t k) noexcept {
        return k == 0 || size % k != 0 ? SIZE_MAX : size / k;
    }
    PleatTransfer *raw_ = nullptr;
};

/// The skin and morph targets a LOD must follow (wraps PleatDeformation): set
/// `PleatLodParams::deformation` to `get()`. Copies every array at construction; the object
/// must outlive the bakes that use it.
class Deformation {
  public:
    Deformation() = default;
    /// `joints` and `weights`: `influences` per input vertex; `pivots`: 3 per joint (may be
    /// empty); `morph_deltas`: 3 per vertex per target, target after target (may be empty);
    /// `max_rotation` in radians and `max_skin_error` in pixels (0: the defaults, 1 rad and
    /// half a pixel).
    Deformation(size_t vertex_count, uint32_t influences, const std::vector<uint32_t> &joints,
                const std::vector<float> &weights, const std::vector<double> &pivots = {},
                const std::vector<float> &morph_deltas = {}, double max_rotation = 0.0,
                double max_skin_error = 0.0) {
        PleatDeformationDesc d = pleat_deformation_desc_default();
        size_t expected = vertex_count * influences;
        if (joints.size() != expected || weights.size() != expected)
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT,
                        "joints and weights need vertex_count x influences values each");
        if (pivots.size() % 3 != 0 || (vertex_count != 0 && morph_deltas.size() % (3 * vertex_count) != 0))
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT,
                        "pivots need 3 values per joint, morph_deltas 3 per vertex per target");
        d.vertex_count = vertex_count;
        d.influences = influences;
        d.joints = joints.empty() ? nullptr : joints.data();
        d.weights = weights.empty() ? nullptr : weights.data();
        d.joint_count = pivots.size() / 3;
        d.joint_pivots = pivots.empty() ? nullptr : pivots.data();
        d.morph_count = vertex_count == 0 ? 0 : morph_deltas.size() / (3 * vertex_count);
        d.morph_deltas = morph_deltas.empty() ? nullptr : morph_deltas.data();
        d.max_rotation = max_rotation;
        d.max_skin_error = max_skin_error;
        check(pleat_deformation_create(&d, &raw_));
    }
    Deformation(const Deformation &) = delete;
    Deformation &operator=(const Deformation &) = delete;
    Deformation(Deformation &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Deformation &operator=(Deformation &&o) noexcept {
        if (this != &o) {
            pleat_deformation_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Deformation() { pleat_deformation_destroy(raw_); }

    const PleatDeformation *get() const noexcept { return raw_; }

  private:
    PleatDeformation *raw_ = nullptr;
};

/// Default bake parameters with `screen_size` (the LOD's n_p) set.
inline PleatBakeParams bake_params(double screen_size = 200.0) noexcept {
    PleatBakeParams p = pleat_bake_params_default();
    p.screen_size = screen_size;
    return p;
}

/// A LOD with the input's appearance baked on (wraps PleatBake*): mesh arrays with atlas UVs,
/// tangents and RGBA8 images (or vertex colours for an untextured input).
class Bake {
  public:
    Bake() = default;
    /// Takes ownership of a handle returned by the C API.
    explicit Bake(PleatBake *raw) noexcept : raw_(raw) {}
    Bake(const Bake &) = delete;
    Bake &operator=(const Bake &) = delete;
    Bake(Bake &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Bake &operator=(Bake &&o) noexcept {
        if (this != &o) {
            pleat_bake_free(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~Bake() { pleat_bake_free(raw_); }

    /// Bakes `material` (the input's appearance, its arrays borrowed for the call) onto `lod`
    /// (pleat_bake_lod).
    static Bake make(const Mesh &lod, const Mesh &input, const PleatBakeMaterial &material,
                     const PleatBakeParams &params = pleat_bake_params_default(),
                     const Progress &progress = {}) {
        PleatBake *b = nullptr;
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_bake_lod(lod.get(), input.get(), &material, &params,
                                    relay.callback(), relay.user_data(), &b, nullptr));
        return Bake(b);
    }

    /// Bakes several materials onto `lod` (pleat_bake_lod_multi): input triangle `t` takes
    /// `materials[triangle_material[t]]`; the mesh arrays (UVs, normals, colours) come from
    /// `materials[0]`, the others set only factors, images and wrap.
    static Bake make(const Mesh &lod, const Mesh &input,
                     const std::vector<PleatBakeMaterial> &materials,
                     const std::vector<uint32_t> &triangle_material,
                     const PleatBakeParams &params = pleat_bake_params_default(),
                     const Progress &progress = {}) {
        PleatBake *b = nullptr;
        detail::ProgressRelay relay(progress);
        relay.finish(pleat_bake_lod_multi(
            lod.get(), input.get(), materials.data(), materials.size(),
            triangle_material.empty() ? nullptr : triangle_material.data(),
            triangle_material.size(), &params, relay.callback(), relay.user_data(), &b,
            nullptr));
        return Bake(b);
    }

    size_t vertex_count() const noexcept { return pleat_bake_vertex_count(raw_); }
    size_t triangle_count() const noexcept { return pleat_bake_triangle_count(raw_); }
    /// Statistics (seconds per stage, texels, charts, appearance error).
    PleatBakeStats stats() const {
        PleatBakeStats s{};
        s.struct_size = sizeof s;
        check(pleat_bake_get_stats(raw_, &s));
        return s;
    }
    /// True for a textured bake (UVs, tangents, images); false: vertex colours.
    bool textured() const { return (stats().flags & PLEAT_BAKE_TEXTURED) != 0; }
    /// xyz doubles per vertex.
    std::vector<double> positions() const {
        std::vector<double> v(3 * vertex_count());
        check(pleat_bake_copy_positions(raw_, v.data(), vertex_count()));
        return v;
    }
    /// 3 indices per triangle.
    std::vector<uint32_t> indices() const {
        std::vector<uint32_t> v(3 * triangle_count());
        check(pleat_bake_copy_indices(raw_, v.data(), v.size()));
        return v;
    }
    /// (u, v) floats per vertex in [0, 1] (textured bakes).
    std::vector<float> uvs() const { return copy(&pleat_bake_copy_uvs, 2); }
    /// Unit normals, xyz floats per vertex.
    std::vector<float> normals() const { return copy(&pleat_bake_copy_normals, 3); }
    /// MikkTSpace tangents, xyzw floats per vertex (textured bakes).
    std::vector<float> tangents() const { return copy(&pleat_bake_copy_tangents, 4); }
    /// Linear RGBA floats per vertex (untextured bakes).
    std::vector<float> colors() const { return copy(&pleat_bake_copy_colors, 4); }
    /// Baked image `which` (PLEAT_BAKE_IMAGE_*) as RGBA8 bytes, `width`/`height` set; empty
    /// when the bake has none.
    std::vector<uint8_t> image(uint32_t which, uint32_t &width, uint32_t &height) const {
        check(pleat_bake_image_size(raw_, which, &width, &height));
        std::vector<uint8_t> v(size_t(4) * width * height);
        if (!v.empty()) check(pleat_bake_copy_image(raw_, which, v.data(), v.size()));
        return v;
    }
    /// Writes a .glb (mesh, material, embedded PNG textures).
    void write_glb(const std::string &path) const {
        check(pleat_bake_write_glb(raw_, path.c_str()));
    }

    const PleatBake *get() const noexcept { return raw_; }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    using CopyFn = PleatStatus (*)(const PleatBake *, float *, size_t);
    std::vector<float> copy(CopyFn fn, size_t k) const {
        std::vector<float> v(k * vertex_count());
        check(fn(raw_, v.data(), vertex_count()));
        return v;
    }
    PleatBake *raw_ = nullptr;
};

/// Tension-field wrinkle solve parameters (pleat_tfw_params_default()).
inline PleatTfwParams tfw_params() noexcept { return pleat_tfw_params_default(); }

/// The result of a tension-field wrinkle solve (wraps PleatTfwResult*): base surface, wrinkle
/// field, stats and the SQP history. Made by TfwScene::solve.
class TfwResult {
  public:
    TfwResult() = default;
    explicit TfwResult(PleatTfwResult *raw) noexcept : raw_(raw) {}
    TfwResult(const TfwResult &) = delete;
    TfwResult &operator=(const TfwResult &) = delete;
    TfwResult(TfwResult &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    TfwResult &operator=(TfwResult &&o) noexcept {
        if (this != &o) {
            pleat_tfw_result_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~TfwResult() { pleat_tfw_result_destroy(raw_); }

    /// Status (PLEAT_TFW_STATUS_*), energies, residuals, iterations, seconds per stage.
    PleatTfwStats stats() const {
        PleatTfwStats s{};
        s.struct_size = sizeof s;
        check(pleat_tfw_result_get_stats(raw_, &s));
        return s;
    }
    /// The base surface.
    Mesh base_mesh() const {
        PleatMesh *m = nullptr;
        check(pleat_tfw_result_base_mesh(raw_, &m));
        return Mesh(m);
    }
    /// The complex wrinkle field on the base mesh (evaluate it with Cwf::evaluate).
    Cwf cwf() const {
        PleatCwf *c = nullptr;
        check(pleat_tfw_result_cwf(raw_, &c));
        return Cwf(c);
    }
    /// The wrinkled mesh after `levels` Loop refinements, with the in-plane v2 term of
    /// eq. 2.19 unless `in_plane_v2` is false.
    Mesh evaluate(uint32_t levels = 3, bool in_plane_v2 = true,
                  const Progress &keep_going = {}) const {
        PleatWrinkleEvalParams p = pleat_wrinkle_eval_params_default();
        p.levels = levels;
        detail::ProgressRelay relay(keep_going);
        PleatMesh *m = nullptr;
        relay.finish(pleat_tfw_result_evaluate(raw_, &p, in_plane_v2 ? 1 : 0, relay.callback(),
                                               relay.user_data(), &m));
        return Mesh(m);
    }
    /// The library's wave counter on the field evaluated with `levels` refinements: the
    /// automatic section when `point` and `normal` are null, else the plane through `point`
    /// with `normal` (a closed ring about `point` when `closed`); samples closer than
    /// `min_radius` (m) to the line through the point along the normal are dropped.
    PleatTfwWaveCount count_waves(uint32_t levels = 2, const double point[3] = nullptr,
                                  const double normal[3] = nullptr, bool closed = false,
                                  double min_radius = 0.0) const {
        PleatTfwWaveCount w{};
        w.struct_size = sizeof w;
        w.min_radius = min_radius;
        check(pleat_tfw_result_count_waves(raw_, levels, point, normal, closed ? 1 : 0, &w));
        return w;
    }
    /// SQP history: PLEAT_TFW_HISTORY_COLUMNS (4) doubles per iteration (energy, stationarity
    /// residual, step, wall seconds), flattened.
    std::vector<double> history() const {
        size_t n = pleat_tfw_result_history_count(raw_);
        std::vector<double> v(PLEAT_TFW_HISTORY_COLUMNS * n + 1);
        check(pleat_tfw_result_copy_history(raw_, v.data(), n));
        v.resize(PLEAT_TFW_HISTORY_COLUMNS * n);
        return v;
    }
    const PleatTfwResult *get() const noexcept { return raw_; }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatTfwResult *raw_ = nullptr;
};

/// A validated tension-field wrinkle scene (wraps PleatTfwScene*): from a JSON file, JSON
/// text or one panel's arrays.
class TfwScene {
  public:
    TfwScene() = default;
    explicit TfwScene(PleatTfwScene *raw) noexcept : raw_(raw) {}
    TfwScene(const TfwScene &) = delete;
    TfwScene &operator=(const TfwScene &) = delete;
    TfwScene(TfwScene &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    TfwScene &operator=(TfwScene &&o) noexcept {
        if (this != &o) {
            pleat_tfw_scene_destroy(raw_);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    ~TfwScene() { pleat_tfw_scene_destroy(raw_); }

    /// Reads a scene file (JSON).
    static TfwScene read(const std::string &path) {
        PleatTfwScene *s = nullptr;
        check(pleat_tfw_scene_read_file(path.c_str(), &s));
        return TfwScene(s);
    }
    /// Parses JSON text.
    static TfwScene from_json(const std::string &json) {
        PleatTfwScene *s = nullptr;
        check(pleat_tfw_scene_from_json(json.c_str(), &s));
        return TfwScene(s);
    }
    /// One flat panel: rest uv (2 per vertex), triangles (3 per triangle), initial positions
    /// (3 per vertex; empty = rest at z = 0), clamped vertices moved by `translation`.
    static TfwScene from_arrays(const std::vector<double> &rest,
                                const std::vector<uint32_t> &triangles,
                                const std::vector<double> &positions = {},
                                const std::vector<uint32_t> &clamped = {},
                                const double translation[3] = nullptr,
                                const PleatTfwMaterial &material = pleat_tfw_material_default()) {
        if (rest.size() % 2 != 0 || triangles.size() % 3 != 0 ||
            (!positions.empty() && positions.size() != rest.size() / 2 * 3))
            throw Error(PLEAT_STATUS_INVALID_ARGUMENT,
                        "rest: 2 doubles per vertex, triangles: 3 indices, positions: 3 doubles "
                        "per vertex (or empty)");
        PleatTfwScene *s = nullptr;
        check(pleat_tfw_scene_from_arrays(
            rest.data(), rest.size() / 2, triangles.data(), triangles.size() / 3,
            positions.empty() ? nullptr : positions.data(), &material, clamped.data(),
            clamped.size(), translation, &s));
        return TfwScene(s);
    }
    /// Adds a plane or sphere obstacle (start from pleat_tfw_obstacle_default()); invalid
    /// fields throw, naming the field, and leave the scene unchanged.
    void add_obstacle(const PleatTfwObstacle &obstacle) {
        check(pleat_tfw_scene_add_obstacle(raw_, &obstacle));
    }
    /// Solves the scene (base surface, wrinkle SQP, phase). `keep_going(stage, fraction)`
    /// returns false to cancel.
    TfwResult solve(const PleatTfwParams &params = pleat_tfw_params_default(),
                    const Progress &keep_going = {}) const {
        detail::ProgressRelay relay(keep_going);
        PleatTfwResult *r = nullptr;
        relay.finish(pleat_tfw_solve(raw_, &params, relay.callback(), relay.user_data(), &r));
        return TfwResult(r);
    }
    const PleatTfwScene *get() const noexcept { return raw_; }
    explicit operator bool() const noexcept { return raw_ != nullptr; }

  private:
    PleatTfwScene *raw_ = nullptr;
};

}  // namespace pleat

#endif  // PLEAT_HPP
