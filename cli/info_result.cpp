// `erodem info RESULT.h5`: what a result file holds — who wrote it and how (version,
// command, backend), the grid, the fields and snapshot times, whether and where it can be
// restarted, and the run's books at its last step (the ledger's volumes, closures, maxima).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/io/results.hpp"
#include "erodem/simulation.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace fs = std::filesystem;

bool is_hdf5_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  in.read(head, sizeof head);
  return in.gcount() == 8 && std::string(head, 8) == std::string("\x89HDF\r\n\x1a\n", 8);
}

namespace {

/// The name a WKT gives its CRS (its first quoted string), or "" for none.
std::string crs_name(const std::string& wkt) {
  const auto a = wkt.find('"');
  const auto b = a == std::string::npos ? a : wkt.find('"', a + 1);
  return b == std::string::npos ? "" : wkt.substr(a + 1, b - a - 1);
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

int info_result(const std::string& path, bool json) {
  const io::ResultReader r(path);
  const Grid& g = r.grid();
  const auto fields = r.fields();
  const auto& times = r.times();
  const auto diag = r.diagnostics();
  const bool restartable = r.has_restart_state();
  const auto restart_times = r.restart_times();  // output.restart_every: maybe not all
  std::error_code ec;
  const auto bytes = fs::file_size(path, ec);
  double dx_min = g.dx.empty() ? 0 : g.dx.front(), dx_max = dx_min;
  for (double d : g.dx) dx_min = std::min(dx_min, d), dx_max = std::max(dx_max, d);
  const std::string crs = crs_name(g.georef.crs_wkt);
  const Diagnostics last = diag.empty() ? Diagnostics{} : diag.back();

  if (json) {
    std::string s = "{\n";
    auto field = [&s](const std::string& key, const std::string& value, bool end = false) {
      s += "  " + json_string(key) + ": " + value + (end ? "\n" : ",\n");
    };
    field("path", json_string(path));
    field("kind", json_string("result"));
    field("bytes", std::to_string(ec ? 0 : bytes));
    for (const char* a : {"erodem_version", "git_describe", "created", "command_line", "backend",
                          "device", "backend_reason", "dem_path", "dem_sha256"})
      field(a, json_string(r.attribute(a)));
    field("nx", std::to_string(g.nx));
    field("ny", std::to_string(g.ny));
    field("crs", crs.empty() ? "null" : json_string(crs));
    field("cell_size_m",
          "{\"dx_min\": " + json_number(dx_min) + ", \"dx_max\": " + json_number(dx_max) + "}");
    std::string f = "[";
    for (std::size_t i = 0; i < fields.size(); ++i) f += (i ? ", " : "") + json_string(fields[i]);
    field("fields", f + "]");
    std::string t = "[";
    for (std::size_t i = 0; i < times.size(); ++i) t += (i ? ", " : "") + json_number(times[i]);
    field("times_s", t + "]");
    field("restart_state", restartable ? "true" : "false");
    std::string rt = "[";
    for (std::size_t i = 0; i < restart_times.size(); ++i)
      rt += (i ? ", " : "") + json_number(restart_times[i]);
    field("restart_times_s", rt + "]");
    field("steps", std::to_string(diag.size()));
    std::string d = "{";
    for (std::size_t i = 0; i < diagnostics_series().size(); ++i) {
      const auto& e = diagnostics_series()[i];
      d += (i ? ", " : "") + json_string(e.name) + ": " + json_number(last.*e.member);
    }
    field("last_step", diag.empty() ? "null" : d + "}", true);
    s += "}\n";
    std::fputs(s.c_str(), stdout);
    return 0;
  }

  std::printf("result file  %s (%.4g MB)\n", path.c_str(), ec ? 0.0 : bytes / 1e6);
  std::printf("written by   erodem %s (%s), %s\n", r.attribute("erodem_version").c_str(),
              r.attribute("git_describe").c_str(), r.attribute("created").c_str());
  std::printf("command      %s\n", r.attribute("command_line").c_str());
  std::printf("backend      %s: %s (%s)\n", r.attribute("backend").c_str(),
              r.attribute("device").c_str(), r.attribute("backend_reason").c_str());
  std::printf("DEM          %s\n", r.attribute("dem_path").c_str());
  std::printf("grid         %d x %d cells, dx %s .. %s m, CRS %s\n", g.nx, g.ny,
              num(dx_min).c_str(), num(dx_max).c_str(), crs.empty() ? "none" : crs.c_str());
  std::printf("fields       %s (%zu)\n", join(fields).c_str(), fields.size());
  if (times.empty())
    std::printf("snapshots    none\n");
  else
    std::printf("snapshots    %zu: t = %s .. %s s\n", times.size(), num(times.front()).c_str(),
                num(times.back()).c_str());
  if (restartable) {
    std::vector<std::string> t;
    for (double v : restart_times) t.push_back(num(v));
    const std::string at =
        restart_times.size() == times.size()
            ? std::string("every snapshot")
            : fmt::format("{} of the {} snapshots", restart_times.size(), times.size());
    std::printf(
        "restart      the full state at %s: erodem run CONFIG --restart %s:TIME with TIME one "
        "of %s s\n",
        at.c_str(), path.c_str(), join(t).c_str());
  } else {
    std::printf("restart      none (written with output.restart_state = false)\n");
  }
  if (diag.empty()) {
    std::printf("steps        none recorded\n");
    return 0;
  }
  std::printf("steps        %zu, to t = %s s (last dt %s s)\n", diag.size(), num(last.time).c_str(),
              num(last.dt).c_str());
  std::printf(
      "water (m^3)  on the grid %s; rain %s, inflow %s, out %s, evaporated %s; closure "
      "%s (%s of what moved)\n",
      num(last.water_volume).c_str(), num(last.rain_volume).c_str(),
      num(last.inflow_volume).c_str(), num(last.boundary_outflow_volume).c_str(),
      num(last.evaporated_volume).c_str(), num(last.closure_error).c_str(),
      num(last.relative_closure_error).c_str());
  std::printf("material     eroded %s m^3, deposited %s m^3; closure %s m^3 (%s of what moved)\n",
              num(last.eroded_volume).c_str(), num(last.deposited_volume).c_str(),
              num(last.material_closure_error).c_str(),
              num(last.relative_material_closure_error).c_str());
  std::printf("maxima       depth %s m, speed %s m/s (last step)\n", num(last.max_depth).c_str(),
              num(last.max_speed).c_str());
  return 0;
}

}  // namespace erodem::cli
