#pragma once
// Helpers of the bench tests, on top of the shared test support (temporary directory, running
// the sph binary).

#include <sstream>
#include <string>
#include <vector>

#include "support/run_sph.h"
#include "support/temp_dir.h"

namespace sph::test {

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

}  // namespace sph::test
