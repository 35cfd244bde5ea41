// erodem — the field registry both backends share (kernels/field_registry.hpp): a field that
// no hand-written process keeps in a member is made on first write or bind, reads of a field
// not made see one shared array of zeros, and setting such a field to zeros leaves it unmade.
// This is what keeps a run from holding arrays for processes it does not run (the snow pack
// without snow, the momenta without the shallow-water scheme: 13 arrays, 52 B per cell of a
// float32 run before 2026-11-27); docs/performance.md, "Resident memory".
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "field_registry.hpp"

namespace erodem::test {
namespace {

using Field = std::vector<float>;

/// The members FieldRegistry::bind takes by name, as both backends have them.
struct FakeBackend {
  Field bed_, bed_next_, depth_, depth_next_, sediment_, sediment_next_, velocity_x_, velocity_y_,
      hardness_, wetness_, manning_, rain_factor_, bed0_, bed_residual_;
  std::array<Field, 4> flux_;
};

TEST(FieldRegistry, FieldsOfProcessesThatDoNotRunHoldNoArray) {
  FakeBackend b;
  FieldRegistry<Field> r;
  int made = 0;
  r.bind(b, [&made] {
    ++made;
    return Field(8, 0.0f);
  });
  EXPECT_EQ(made, 0) << "bind makes no array";
  EXPECT_EQ(r.get(FieldId::bed), &b.bed_) << "members are bound, not made";
  EXPECT_EQ(r.twin(FieldId::bed), &b.bed_next_);
  EXPECT_EQ(r.get(FieldId::erosion), nullptr) << "a derived field has no storage";
  EXPECT_EQ(r.peek(FieldId::erosion), nullptr);

  // Reads of fields not made: one shared array of zeros, nothing made per field.
  const Field* snow = r.peek(FieldId::snow);
  ASSERT_NE(snow, nullptr);
  EXPECT_EQ(*snow, Field(8, 0.0f));
  EXPECT_EQ(r.peek(FieldId::soil_thickness), snow);
  EXPECT_FALSE(r.made(FieldId::snow));
  EXPECT_EQ(made, 1) << "only the shared zeros";

  // Setting zeros keeps a field unmade; anything else (even -0) makes it.
  EXPECT_TRUE(r.setting_keeps_unmade(FieldId::snow, std::vector<double>(8, 0.0)));
  EXPECT_FALSE(r.setting_keeps_unmade(FieldId::snow, {0, 0, 0, -0.0, 0, 0, 0, 0}));
  EXPECT_FALSE(r.setting_keeps_unmade(FieldId::snow, {0, 0, 0, 1e-30, 0, 0, 0, 0}));
  EXPECT_FALSE(r.setting_keeps_unmade(FieldId::bed, std::vector<double>(8, 0.0)))
      << "a member is always made";

  // Writing or binding makes the field (a twin with its second buffer), once.
  Field* own = r.get(FieldId::snow);
  ASSERT_NE(own, nullptr);
  EXPECT_NE(own, snow);
  EXPECT_TRUE(r.made(FieldId::snow));
  EXPECT_EQ(r.get(FieldId::snow), own);
  EXPECT_EQ(r.peek(FieldId::snow), own);
  (*own)[3] = 2.5f;
  EXPECT_EQ((*r.peek(FieldId::snow))[3], 2.5f);
  EXPECT_EQ((*r.peek(FieldId::soil_thickness))[3], 0.0f) << "the shared zeros stay zeros";
  const int before_twin = made;
  Field* qx = r.get(FieldId::momentum_x);
  ASSERT_NE(r.twin(FieldId::momentum_x), nullptr);
  EXPECT_NE(r.twin(FieldId::momentum_x), qx);
  EXPECT_EQ(made, before_twin + 2) << "a twin field is made with its second buffer";
  EXPECT_FALSE(r.setting_keeps_unmade(FieldId::snow, std::vector<double>(8, 0.0)))
      << "a made field is written";
}

}  // namespace
}  // namespace erodem::test
