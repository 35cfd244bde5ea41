// erodem — the process's resident memory (Linux /proc), for the bench's memory columns and the
// memory tests: the peak resident set (VmHWM), its reset, and the resident set now (VmRSS).
#pragma once

namespace erodem {

/// Sets this process's peak resident set (VmHWM) to its resident set now (Linux >= 4.0,
/// /proc/self/clear_refs); false where it cannot.
bool reset_peak_resident();
/// The peak resident set of this process (VmHWM, bytes); 0 where /proc does not say.
double peak_resident_bytes();
/// The resident set of this process now (VmRSS, bytes); 0 where /proc does not say.
double resident_bytes();

}  // namespace erodem
