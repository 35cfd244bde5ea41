#include "erodem/resident.hpp"

#include <fstream>
#include <string>

namespace erodem {

namespace {

/// The value of `key` ("VmHWM:", "VmRSS:") of /proc/self/status in bytes; 0 where absent.
double status_bytes(const char* key) {
  std::ifstream status("/proc/self/status");
  const std::string k = key;
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(k, 0) == 0) return 1024.0 * std::stod(line.substr(k.size()));  // kB
  return 0;
}

}  // namespace

bool reset_peak_resident() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

double peak_resident_bytes() {
  return status_bytes("VmHWM:");
}

double resident_bytes() {
  return status_bytes("VmRSS:");
}

}  // namespace erodem
