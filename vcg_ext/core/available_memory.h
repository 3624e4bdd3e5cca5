// How much memory this process may still allocate, read from Linux's /proc and cgroup files; the
// memory checks of the pipeline, the report and the volumetric rebuild compare their estimates to it.
#pragma once

#include <algorithm>
#include <fstream>
#include <string>

namespace molremesh {
namespace memory_detail {

inline double ReadMeminfoKB(const std::string& key) {
  std::ifstream in("/proc/meminfo");
  std::string name;
  double value = 0;
  std::string unit;
  while (in >> name >> value) {
    std::getline(in, unit);
    if (name == key) return value;
  }
  return 0;
}

inline double ReadNumber(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  if (!(in >> word) || word == "max") return 0;
  try {
    return std::stod(word);
  } catch (...) {
    return 0;
  }
}

/// The process's cgroup (v2, else v1 memory controller): limit minus usage, 0 when unlimited
/// or unknown.
inline double CgroupRoom() {
  std::ifstream in("/proc/self/cgroup");
  std::string line, v2Path, v1Path;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) == 0) v2Path = line.substr(3);
    const std::size_t at = line.find(":memory:");
    if (at != std::string::npos) v1Path = line.substr(at + 8);
  }
  auto room = [](double limit, double usage) {
    // Unlimited cgroups report a limit near 2^63.
    if (!(limit > 0) || limit > 1e18) return 0.0;
    return std::max(1.0, limit - usage);
  };
  for (const std::string& dir : {"/sys/fs/cgroup" + v2Path, std::string("/sys/fs/cgroup")}) {
    const double r = room(ReadNumber(dir + "/memory.max"), ReadNumber(dir + "/memory.current"));
    if (r > 0) return r;
  }
  for (const std::string& dir : {"/sys/fs/cgroup/memory" + v1Path, std::string("/sys/fs/cgroup/memory")}) {
    const double r =
        room(ReadNumber(dir + "/memory.limit_in_bytes"), ReadNumber(dir + "/memory.usage_in_bytes"));
    if (r > 0) return r;
  }
  return 0;
}

} // namespace memory_detail

/// Bytes this process may still allocate: the system's available memory (Linux: MemAvailable)
/// and, inside a container, its cgroup's limit minus its usage. 0 when unknown (the check is
/// then skipped).
inline double AvailableMemoryBytes() {
  double available = memory_detail::ReadMeminfoKB("MemAvailable:") * 1024.0;
  const double cgroupRoom = memory_detail::CgroupRoom();
  if (cgroupRoom > 0) available = available > 0 ? std::min(available, cgroupRoom) : cgroupRoom;
  return available;
}

} // namespace molremesh
