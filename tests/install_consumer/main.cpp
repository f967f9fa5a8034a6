// Builds a 4x4 MSM object from the installed headers and library and presses it once.
#include <pliant/core/msm.hpp>

#include <cstdio>
#include <vector>

int main() {
  std::vector<double> rest;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      rest.push_back(x);
      rest.push_back(y);
    }
  }
  std::vector<std::uint8_t> fixed(16, 0);
  for (int x = 0; x < 4; ++x) fixed[static_cast<std::size_t>(x)] = 1;
  const int tool = 13;
  pliant::MsmModelConfig<2, double> config;
  config.particle_count = 16;
  config.rest_positions = rest.data();
  config.fixed = fixed.data();
  config.drivable_ids = &tool;
  config.drivable_count = 1;
  std::vector<unsigned char> model_block(pliant::msm_model_workspace_size(config));
  pliant::Arena model_arena(model_block.data(), model_block.size());
  pliant::MsmModel<2, double> model;
  if (pliant::msm_model_init(model_arena, config, model) != pliant::Status::ok) return 1;
  std::vector<unsigned char> state_block(pliant::msm_state_workspace_size(model));
  pliant::Arena state_arena(state_block.data(), state_block.size());
  pliant::MsmState<2, double> state;
  if (pliant::msm_state_init(state_arena, model, state) != pliant::Status::ok) return 1;
  pliant::MsmParams<2, double> params;
  params.msm_beta = 0.5;
  Eigen::Vector2d target(1.0, 2.7);
  pliant::MsmStepInput<2, double> input;
  input.dt = 1.0 / 30;
  input.driven = {&tool, &target, 1};
  for (int k = 0; k < 30; ++k) {
    if (pliant::msm_step(model, params, input, state) != pliant::Status::ok) return 1;
  }
  const double sag = 3.0 - state.position[14].y();
  std::printf("consumer: neighbour of the pressed particle moved down %.3f\n", sag);
  return sag > 0.01 ? 0 : 1;
}
