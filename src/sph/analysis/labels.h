#pragma once
/// \file Turning run labels into names for CSV columns and files (shared by the analyses).

#include <cctype>
#include <string>

namespace sph {

/// A run label as a CSV column or file name part: letters and digits kept, every other run of
/// characters one '_', none at the ends ("standard (perturbed)" -> "standard_perturbed").
inline std::string slug(const std::string& label) {
  std::string s;
  for (char c : label) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      s += c;
    else if (!s.empty() && s.back() != '_')
      s += '_';
  }
  while (!s.empty() && s.back() == '_') s.pop_back();
  return s;
}

}  // namespace sph
