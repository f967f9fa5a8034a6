#include "plant_finger.hpp"

#include <limits>

namespace pliant::hil {

double PlantFinger::force_n(double width_m) const noexcept { return plant_.force_at(plant_.extent_m() - width_m); }

double PlantFinger::width_at_force(double force_n) const noexcept {
  const double extent = plant_.extent_m();
  double high = extent * plant_.config().max_closure_fraction;  // the plant's hard stop
  if (!(plant_.force_at(high) >= force_n)) return std::numeric_limits<double>::quiet_NaN();
  double low = 0;  // force_at(low) < force_n <= force_at(high): halve to well below a nanometre
  for (int i = 0; i < 48; ++i) {
    const double mid = 0.5 * (low + high);
    if (plant_.force_at(mid) >= force_n) {
      high = mid;
    } else {
      low = mid;
    }
  }
  return extent - high;
}

}  // namespace pliant::hil
