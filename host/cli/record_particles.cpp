#include "record_particles.hpp"

#include <stdexcept>

namespace pliant::cli {

host::Recording jaw_recording(const std::vector<GripperRow>& rows, const std::string& name) {
  if (rows.empty()) {
    throw std::runtime_error("the gripper delivered no reading, so there are no particles (the jaws) to record");
  }
  host::Recording r;
  r.name = name;
  r.dimension = 2;
  r.length_unit = "m";
  r.particle_count = 2;
  r.masses = {1.0, 1.0};
  r.fixed = {0};
  host::DrivenWindow jaw_b;
  jaw_b.id = 1;
  r.driven = {jaw_b};
  r.frame_times_s.reserve(rows.size());
  r.positions.reserve(rows.size() * 4);
  for (const GripperRow& row : rows) {
    r.frame_times_s.push_back(row.t_s);
    r.positions.insert(r.positions.end(), {0.0, 0.0, row.width_m, 0.0});
  }
  return r;
}

}  // namespace pliant::cli
