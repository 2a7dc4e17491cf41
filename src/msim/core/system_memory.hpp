#pragma once
// How much memory this machine can give a run, so scenes too large for it are refused before
// anything is allocated.
#include <cstddef>
#include <string>

namespace msim {

// MemAvailable from /proc/meminfo (physical pages free or reclaimable); falls back to the
// physical total where /proc is unavailable.
std::size_t availableMemoryBytes();
std::string formatBytes(double bytes);

}  // namespace msim
