// erodem — the OpenCL program: assembled from the embedded kernels/opencl/*.cl and
// kernels/common/*.h (each header once, every line's origin kept), built on a runtime's
// device, and a failed build's log annotated with the original files and lines.
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "erodem/error.hpp"
#include "erodem/process.hpp"
#include "opencl/embedded_sources.hpp"
#include "opencl/opencl_backend.hpp"

namespace erodem::opencl {

namespace {

const EmbeddedSource* find_embedded(const std::string& name) {
  for (std::size_t k = 0; k < kEmbeddedSourceCount; ++k)
    if (name == kEmbeddedSources[k].name) return &kEmbeddedSources[k];
  return nullptr;
}

/// Appends `name` to `out`, expanding #include "x.h" lines (each file once: all carry
/// include guards).
void expand(const std::string& name, ProgramSource& out, std::set<std::string>& included,
            int depth) {
  const EmbeddedSource* src = find_embedded(name);
  if (!src) throw Error(ExitCode::internal, "OpenCL sources: '" + name + "' is not embedded");
  if (depth > 16) throw Error(ExitCode::internal, "OpenCL sources: #include nesting too deep");
  static const std::regex include_re(R"(^\s*#\s*include\s*"([^"]+)\"\s*$)");
  std::istringstream in(src->text);
  std::string line;
  int number = 0;
  auto emit = [&](const std::string& text, int at) {
    out.text += text;
    out.text += '\n';
    out.origin.push_back({name, at});
  };
  while (std::getline(in, line)) {
    ++number;
    std::smatch m;
    if (std::regex_match(line, m, include_re)) {
      const std::string header = m[1].str();
      if (!included.insert(header).second) {
        emit("/* " + header + ": already included */", number);
        continue;
      }
      emit("/* ---- begin " + header + " (included from " + name + ") ---- */", number);
      expand(header, out, included, depth + 1);
      emit("/* ---- end " + header + " ---- */", number);
    } else {
      emit(line, number);
    }
  }
}

}  // namespace

ProgramSource assemble_program() {
  // What the reductions share, the process files in step order, then the reductions; every
  // other embedded .cl after.
  std::vector<std::string> order = opencl_program_order();  // from the process table
  for (std::size_t k = 0; k < kEmbeddedSourceCount; ++k) {
    const std::string name = kEmbeddedSources[k].name;
    if (name.size() > 3 && name.compare(name.size() - 3, 3, ".cl") == 0 &&
        std::find(order.begin(), order.end(), name) == order.end())
      order.push_back(name);
  }
  ProgramSource out;
  std::set<std::string> included;
  for (const auto& name : order) {
    out.text += "/* ==== " + name + " ==== */\n";
    out.origin.push_back({name, 0});
    expand(name, out, included, 0);
  }
  return out;
}

std::string annotate_build_log(const std::string& log, const ProgramSource& src) {
  static const std::regex loc_re(R"(:(\d+):(\d+):)");
  std::istringstream in(log);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    out << line << '\n';
    std::smatch m;
    if (!std::regex_search(line, m, loc_re)) continue;
    const long n = std::stol(m[1].str());
    if (n < 1 || n > static_cast<long>(src.origin.size())) continue;
    const auto& o = src.origin[static_cast<std::size_t>(n - 1)];
    // The offending line, from the assembled text.
    std::size_t begin = 0;
    for (long k = 1; k < n && begin != std::string::npos; ++k) {
      begin = src.text.find('\n', begin);
      if (begin != std::string::npos) ++begin;
    }
    std::string text;
    if (begin != std::string::npos) {
      const auto end = src.text.find('\n', begin);
      text = src.text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    }
    out << "    --> " << o.file << ':' << o.line << ':' << m[2].str() << ": " << text << '\n';
  }
  return out.str();
}

void build_program(Runtime& rt) {
  const ProgramSource src = assemble_program();
  if (const char* dir = std::getenv("ERODEM_OPENCL_DUMP"); dir && *dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    std::ofstream(std::filesystem::path(dir) / "erodem_program.cl") << src.text;
    std::ofstream(std::filesystem::path(dir) / "erodem_build_options.txt") << rt.options << '\n';
  }
  const char* text = src.text.c_str();
  const std::size_t length = src.text.size();
  cl_int err = CL_SUCCESS;
  rt.program = Program(clCreateProgramWithSource(rt.context.get(), 1, &text, &length, &err));
  check(err, "clCreateProgramWithSource");
  cl_device_id device = rt.device;
  err = clBuildProgram(rt.program.get(), 1, &device, rt.options.c_str(), nullptr, nullptr);
  if (err != CL_SUCCESS) {
    std::size_t size = 0;
    std::string log;
    if (clGetProgramBuildInfo(rt.program.get(), device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size) ==
            CL_SUCCESS &&
        size > 0) {
      log.resize(size);
      clGetProgramBuildInfo(rt.program.get(), device, CL_PROGRAM_BUILD_LOG, size, log.data(),
                            nullptr);
      while (!log.empty() && log.back() == '\0') log.pop_back();
    }
    rt.program.reset();
    throw Error(ExitCode::internal,
                fmt::format("OpenCL: building the kernels for '{} / {}' failed: {} ({}); options "
                            "'{}'; CL_PROGRAM_BUILD_LOG:\n{}",
                            rt.info.platform, rt.info.device, error_name(err), err, rt.options,
                            annotate_build_log(log, src)));
  }
}

}  // namespace erodem::opencl
