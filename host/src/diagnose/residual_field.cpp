#include "pliant/host/diagnose/residual_field.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace pliant::host {
namespace {

void check_mask(const std::vector<unsigned char>* mask, int entries, const char* what) {
  if (mask != nullptr && mask->size() != static_cast<std::size_t>(entries)) throw std::invalid_argument(what);
}

bool selected(const std::vector<unsigned char>* mask, int index) {
  return mask == nullptr || (*mask)[static_cast<std::size_t>(index)] != 0;
}

// Sum of |r|^2 and count over the pairs with particle-major (per_particle) or frame-major
// grouping; `group` is the particle (or frame) index of each output entry.
void accumulate(const ResidualField& field, bool per_particle, const std::vector<unsigned char>* mask,
                std::vector<double>& sum, std::vector<int>& count) {
  const int groups = per_particle ? field.particle_count : field.frame_count;
  sum.assign(static_cast<std::size_t>(groups), 0.0);
  count.assign(static_cast<std::size_t>(groups), 0);
  for (int k = 0; k < field.frame_count; ++k) {
    for (int i = 0; i < field.particle_count; ++i) {
      if (!selected(mask, per_particle ? k : i)) continue;
      const double squared = field.squared_norm(k, i);
      if (!std::isfinite(squared)) continue;
      const auto g = static_cast<std::size_t>(per_particle ? i : k);
      sum[g] += squared;
      count[g] += 1;
    }
  }
}

std::vector<double> rms_of(const std::vector<double>& sum, const std::vector<int>& count) {
  std::vector<double> out(sum.size(), 0.0);
  for (std::size_t g = 0; g < sum.size(); ++g) {
    if (count[g] > 0) out[g] = std::sqrt(sum[g] / static_cast<double>(count[g]));
  }
  return out;
}

}  // namespace

bool ResidualField::observed(int frame, int id) const {
  const double* r = at(frame, id);
  for (int d = 0; d < dimension; ++d) {
    if (!std::isfinite(r[d])) return false;
  }
  return true;
}

double ResidualField::squared_norm(int frame, int id) const {
  if (!observed(frame, id)) return std::numeric_limits<double>::quiet_NaN();
  const double* r = at(frame, id);
  double squared = 0;
  for (int d = 0; d < dimension; ++d) squared += r[d] * r[d];
  return squared;
}

ResidualField make_residual_field(const std::vector<double>& observed, const std::vector<double>& simulated,
                                  int particle_count, int dimension) {
  if (dimension < 1 || particle_count < 0)
    throw std::invalid_argument("residual field: bad dimension or particle count");
  if (observed.size() != simulated.size())
    throw std::invalid_argument("residual field: observed and simulated differ in size");
  ResidualField field;
  field.particle_count = particle_count;
  field.dimension = dimension;
  if (particle_count == 0) {
    if (!observed.empty()) throw std::invalid_argument("residual field: positions given for zero particles");
    return field;
  }
  const std::size_t pair = static_cast<std::size_t>(particle_count) * static_cast<std::size_t>(dimension);
  if (observed.size() % pair != 0)
    throw std::invalid_argument("residual field: size is not a multiple of particle_count * dimension");
  field.frame_count = static_cast<int>(observed.size() / pair);
  field.residual.assign(observed.size(), std::numeric_limits<double>::quiet_NaN());
  const auto dim = static_cast<std::size_t>(dimension);
  for (std::size_t start = 0; start < observed.size(); start += dim) {
    bool finite = true;
    for (std::size_t d = 0; d < dim; ++d) {
      finite = finite && std::isfinite(observed[start + d]) && std::isfinite(simulated[start + d]) &&
               std::isfinite(observed[start + d] - simulated[start + d]);
    }
    if (!finite) continue;
    for (std::size_t d = 0; d < dim; ++d) field.residual[start + d] = observed[start + d] - simulated[start + d];
  }
  return field;
}

std::vector<double> particle_rms(const ResidualField& field, const std::vector<unsigned char>* frame_mask) {
  check_mask(frame_mask, field.frame_count, "particle_rms: frame_mask needs one entry per frame");
  std::vector<double> sum;
  std::vector<int> count;
  accumulate(field, true, frame_mask, sum, count);
  return rms_of(sum, count);
}

std::vector<int> particle_samples(const ResidualField& field, const std::vector<unsigned char>* frame_mask) {
  check_mask(frame_mask, field.frame_count, "particle_samples: frame_mask needs one entry per frame");
  std::vector<double> sum;
  std::vector<int> count;
  accumulate(field, true, frame_mask, sum, count);
  return count;
}

std::vector<double> frame_rms(const ResidualField& field, const std::vector<unsigned char>* particle_mask) {
  check_mask(particle_mask, field.particle_count, "frame_rms: particle_mask needs one entry per particle");
  std::vector<double> sum;
  std::vector<int> count;
  accumulate(field, false, particle_mask, sum, count);
  return rms_of(sum, count);
}

std::vector<int> frame_samples(const ResidualField& field, const std::vector<unsigned char>* particle_mask) {
  check_mask(particle_mask, field.particle_count, "frame_samples: particle_mask needs one entry per particle");
  std::vector<double> sum;
  std::vector<int> count;
  accumulate(field, false, particle_mask, sum, count);
  return count;
}

std::vector<double> residual_magnitudes(const ResidualField& field) {
  std::vector<double> out(static_cast<std::size_t>(field.frame_count) * static_cast<std::size_t>(field.particle_count),
                          std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < field.frame_count; ++k) {
    for (int i = 0; i < field.particle_count; ++i) {
      const double squared = field.squared_norm(k, i);
      if (std::isfinite(squared)) {
        out[static_cast<std::size_t>(k) * static_cast<std::size_t>(field.particle_count) +
            static_cast<std::size_t>(i)] = std::sqrt(squared);
      }
    }
  }
  return out;
}

}  // namespace pliant::host
