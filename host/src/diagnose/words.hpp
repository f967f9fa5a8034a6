// Numbers and particle lists as the diagnosis explanations write them (internal to diagnose/).
#pragma once

#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

namespace pliant::host::words {

/// Three significant digits.
inline std::string number(double v) {
  std::ostringstream out;
  out.precision(3);
  out << v;
  return out.str();
}

/// Sorted ids as runs ("3-7, 12"), the first twelve, then "and N more".
inline std::string id_list(const std::vector<int>& ids) {
  std::ostringstream out;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (i > 0) out << ", ";
    out << ids[i];
    if (j > i) out << "-" << ids[j];
    i = j + 1;
    if (i >= 12 && i < ids.size()) {
      out << " and " << ids.size() - i << " more";
      break;
    }
  }
  return out.str();
}

}  // namespace pliant::host::words
