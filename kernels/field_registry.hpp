// erodem — the field registry both backends share: every field's storage by FieldId (a
// CPU array or an OpenCL buffer), the second buffer of the twins, and an array of its own for
// every field no hand-written process keeps in a named member (ERODEM_FIELDS, fields.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "common/compat.h"
#include "erodem/fields.hpp"

namespace erodem {

template <class Storage>
class FieldRegistry {
 public:
  /// The storage of field `id`; nullptr for a derived field (the erosion).
  Storage* get(FieldId id) const { return storage_[static_cast<std::size_t>(id)]; }
  /// The second buffer of a twin (FieldInfo::twin); nullptr for the others.
  Storage* twin(FieldId id) const { return twin_[static_cast<std::size_t>(id)]; }

  /// Binds the named members of backend `b` that the hand-written processes use (the same
  /// names in both backends: bed_, bed_next_, depth_, flux_[k], ...; `b` befriends this
  /// class), then gives every other stored field, and the twin of a twin, make_zero() of its
  /// own.
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
    for (const auto& f : field_table()) {
      const auto k = static_cast<std::size_t>(f.id);
      if (f.derived || storage_[k]) continue;
      own_.push_back(std::make_unique<Storage>(make_zero()));
      storage_[k] = own_.back().get();
      if (f.twin) {
        own_.push_back(std::make_unique<Storage>(make_zero()));
        twin_[k] = own_.back().get();
      }
    }
  }

 private:
  void put(FieldId id, Storage* s, Storage* twin = nullptr) {
    storage_[static_cast<std::size_t>(id)] = s;
    twin_[static_cast<std::size_t>(id)] = twin;
  }
  std::array<Storage*, kFieldCount> storage_{}, twin_{};
  std::vector<std::unique_ptr<Storage>> own_;
};

}  // namespace erodem
