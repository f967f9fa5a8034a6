// libFuzzer target over hal::DeviceSpec's typed parameters (hal/src/device_registry.cpp): the
// text of a device spec's parameters as a user types it on the command line. The input is
// "name=value" lines; every accessor is asked for every name with fixed ranges. An accessor
// either returns a value inside its range or throws std::invalid_argument; anything else (a
// crash, a sanitizer report, another exception, a value out of range) is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "pliant/hal/device_registry.hpp"

namespace {

template <typename Call>
void ask(Call call) {
  try {
    call();
  } catch (const std::invalid_argument&) {
  }
}

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  pliant::hal::DeviceSpec spec;
  spec.scheme = "fuzz";
  std::size_t begin = 0;
  while (begin < input.size()) {
    std::size_t end = input.find('\n', begin);
    if (end == std::string_view::npos) end = input.size();
    const std::string_view line = input.substr(begin, end - begin);
    const std::size_t equals = line.find('=');
    if (equals != std::string_view::npos) {
      spec.parameters[std::string(line.substr(0, equals))] = std::string(line.substr(equals + 1));
    }
    begin = end + 1;
  }
  for (const auto& parameter : spec.parameters) {
    const std::string& name = parameter.first;
    check(spec.has(name));
    (void)spec.text(name);
    ask([&] {
      const std::int64_t v = spec.integer(name, -1000, 0xffff, 7);
      check(v >= -1000 && v <= 0xffff);
    });
    ask([&] {
      const std::int64_t v = spec.integer(name, 0, 247);
      check(v >= 0 && v <= 247);
    });
    ask([&] {
      const double v = spec.number(name, -1e3, 1e6, 0.5);
      check(std::isfinite(v) && v >= -1e3 && v <= 1e6);
    });
    ask([&] { (void)spec.flag(name, false); });
    ask([&] {
      const std::string v = spec.choice(name, {"rgb8", "bgr8", "mono8"}, "rgb8");
      check(v == "rgb8" || v == "bgr8" || v == "mono8");
    });
  }
  return 0;
}
