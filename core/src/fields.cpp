#include "erodem/fields.hpp"

#include "erodem/error.hpp"

namespace erodem {

const std::vector<FieldInfo>& field_table() {
  static const std::vector<FieldInfo> table{
#define ERODEM_FIELD_INFO(id, units, long_name, flags) \
  {FieldId::id,                                        \
   #id,                                                \
   units,                                              \
   long_name,                                          \
   ((flags)&kStateField) != 0,                         \
   ((flags)&kOutputField) != 0,                        \
   ((flags)&kRestartZero) != 0,                        \
   ((flags)&kTwinField) != 0,                          \
   ((flags)&kDerivedField) != 0},
      ERODEM_FIELDS(ERODEM_FIELD_INFO)
#undef ERODEM_FIELD_INFO
  };
  return table;
}

const std::vector<FieldId>& state_fields() {
  static const std::vector<FieldId> ids = [] {
    std::vector<FieldId> v;
    for (const auto& f : field_table())
      if (f.state) v.push_back(f.id);
    return v;
  }();
  return ids;
}

const std::vector<std::string>& output_field_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& f : field_table())
      if (f.output) v.emplace_back(f.name);
    return v;
  }();
  return names;
}

const FieldInfo& field_info(const std::string& name) {
  std::string names;
  for (const auto& f : field_table()) {
    if (name == f.name) return f;
    names += names.empty() ? f.name : std::string(", ") + f.name;
  }
  throw Error(ExitCode::config, "unknown field '" + name + "' (known: " + names + ")");
}

const FieldInfo& field_info(FieldId id) {
  const auto k = static_cast<std::size_t>(id);
  if (k < field_table().size()) return field_table()[k];
  throw Error(ExitCode::internal, "field id without a table entry");
}

}  // namespace erodem
