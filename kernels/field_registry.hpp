// erodem — the field registry both backends share: every field's storage by FieldId (a
// CPU array or an OpenCL buffer), the second buffer of the twins, and an array of its own for
// every field no hand-written process keeps in a named member (ERODEM_FIELDS, fields.hpp),
// made when something first writes or binds it: a run whose processes never use a field (the
// snow pack without snow, the momenta without the shallow-water scheme, ...) holds no array
// for it; reads of such a field see one array of zeros shared by all of them.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "common/compat.h"
#include "erodem/fields.hpp"

namespace erodem {

template <class Storage>
class FieldRegistry {
 public:
  /// The storage of field `id` to write or bind, made (zeros) on first use for a field no
  /// member holds, with its twin; nullptr for a derived field (the erosion).
  Storage* get(FieldId id) {
    const auto k = static_cast<std::size_t>(id);
    if (!storage_[k] && lazy_[k]) make(k);
    return storage_[k];
  }
  /// The storage to read field `id` from without making it: its own once made, else one
  /// array of zeros shared by every field not made yet (never written); nullptr for a derived
  /// field.
  const Storage* peek(FieldId id) const {
    const auto k = static_cast<std::size_t>(id);
    if (storage_[k] || !lazy_[k]) return storage_[k];
    if (!zeros_) zeros_ = std::make_unique<Storage>(make_zero_());
    return zeros_.get();
  }
  /// The second buffer of a twin (FieldInfo::twin), made with its field; nullptr for the
  /// others.
  Storage* twin(FieldId id) {
    get(id);
    return twin_[static_cast<std::size_t>(id)];
  }
  /// Whether field `id` has storage of its own now (a member, or made on first use).
  bool made(FieldId id) const { return storage_[static_cast<std::size_t>(id)] != nullptr; }
  /// Whether field `id` reads as zeros because it is not made yet: a reader that can supply
  /// the zeros itself (field()) then needs no array of them (peek makes one, 4 B per cell).
  bool reads_zeros(FieldId id) const {
    const auto k = static_cast<std::size_t>(id);
    return !storage_[k] && lazy_[k];
  }
  /// Whether setting field `id` to `values` can leave it unmade: it is not made yet and every
  /// value is +0, what its reads give already (a restart of a run without snow writes the
  /// snow pack's zeros, which then need no array).
  bool setting_keeps_unmade(FieldId id, const std::vector<double>& values) const {
    const auto k = static_cast<std::size_t>(id);
    if (storage_[k] || !lazy_[k]) return false;
    for (const double v : values)
      if (!(v == 0.0 && !std::signbit(v))) return false;
    return true;
  }

  /// Binds the named members of backend `b` that the hand-written processes use (the same
  /// names in both backends: bed_, bed_next_, depth_, flux_[k], ...; `b` befriends this
  /// class); every other stored field, and the twin of a twin, gets make_zero() of its own
  /// when first asked for by get().
  template <class Backend, class MakeZero>
  void bind(Backend& b, MakeZero make_zero) {
    put(FieldId::bed, &b.bed_, &b.bed_next_);
    put(FieldId::water_depth, &b.depth_, &b.depth_next_);
    put(FieldId::sediment, &b.sediment_, &b.sediment_next_);
    put(FieldId::velocity_x, &b.velocity_x_);
    put(FieldId::velocity_y, &b.velocity_y_);
    put(FieldId::flux_left, &b.flux_[ERODEM_LEFT]);
    put(FieldId::flux_right, &b.flux_[ERODEM_RIGHT]);
    put(FieldId::flux_top, &b.flux_[ERODEM_TOP]);
    put(FieldId::flux_bottom, &b.flux_[ERODEM_BOTTOM]);
    put(FieldId::hardness, &b.hardness_);
    put(FieldId::wetness, &b.wetness_);
    put(FieldId::manning_n, &b.manning_);
    put(FieldId::rain_factor, &b.rain_factor_);
    put(FieldId::initial_bed, &b.bed0_);
    put(FieldId::bed_residual, &b.bed_residual_);
    make_zero_ = make_zero;
    for (const auto& f : field_table()) {
      const auto k = static_cast<std::size_t>(f.id);
      lazy_[k] = !f.derived && !storage_[k];
      has_twin_[k] = f.twin;
    }
  }

 private:
  void put(FieldId id, Storage* s, Storage* twin = nullptr) {
    storage_[static_cast<std::size_t>(id)] = s;
    twin_[static_cast<std::size_t>(id)] = twin;
  }
  void make(std::size_t k) {
    own_.push_back(std::make_unique<Storage>(make_zero_()));
    storage_[k] = own_.back().get();
    if (has_twin_[k]) {
      own_.push_back(std::make_unique<Storage>(make_zero_()));
      twin_[k] = own_.back().get();
    }
  }
  std::array<Storage*, kFieldCount> storage_{}, twin_{};
  std::array<bool, kFieldCount> lazy_{}, has_twin_{};
  std::function<Storage()> make_zero_;
  std::vector<std::unique_ptr<Storage>> own_;
  mutable std::unique_ptr<Storage> zeros_;
};

}  // namespace erodem
