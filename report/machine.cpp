#include "report/machine.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

namespace stvl::report {

nlohmann::json machine_json() {
  std::string cpu, line;
  int cpus = 0;
  std::ifstream cpuinfo("/proc/cpuinfo");
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("processor", 0) == 0) ++cpus;
    if (cpu.empty() && line.rfind("model name", 0) == 0) cpu = line.substr(line.find(':') + 2);
  }
  double memory_gib = 0;
  std::ifstream meminfo("/proc/meminfo");
  while (std::getline(meminfo, line))
    if (line.rfind("MemTotal:", 0) == 0) memory_gib = std::round(std::stod(line.substr(9)) / (1024.0 * 1024.0));
  char host[256] = "";
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  const std::string key =
      cpu + "|" + std::to_string(cpus) + "|" + std::to_string(static_cast<long>(memory_gib)) + "|" + host;
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a, 64 bits
  for (unsigned char c : key) hash = (hash ^ c) * 1099511628211ull;
  char fingerprint[17];
  std::snprintf(fingerprint, sizeof fingerprint, "%016llx", static_cast<unsigned long long>(hash));
  return {
      {"cpu", cpu}, {"logical_cpus", cpus}, {"memory_gib", memory_gib}, {"host", host}, {"fingerprint", fingerprint}};
}

}  // namespace stvl::report
