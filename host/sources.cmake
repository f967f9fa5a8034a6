# Sources of the host libraries, one list per library. Included by host/CMakeLists.txt, which
# builds the libraries, and by tests/fuzz/, which compiles the parsers among them again with
# fuzzer instrumentation (PLIANT_BUILD_HOST=OFF there).
set(pliant_host_src ${CMAKE_CURRENT_LIST_DIR}/src)

# recording v1 I/O (recording.hpp, vtk_mesh.hpp, text_fields.hpp)
set(PLIANT_RECORDING_SOURCES
  ${pliant_host_src}/recording/recording_json.cpp
  ${pliant_host_src}/recording/recording_csv.cpp
  ${pliant_host_src}/recording/vtk_mesh.cpp
  ${pliant_host_src}/recording/recording_io.cpp)
# MSM set-up from a recording and the msm_beta / msm_alpha estimate (msm_setup.hpp, estimate.hpp)
set(PLIANT_ESTIMATION_SOURCES
  ${pliant_host_src}/estimation/msm_setup.cpp
  ${pliant_host_src}/estimation/cluster_radii.cpp
  ${pliant_host_src}/estimation/estimate.cpp)
# tetrahedral meshes and closed surfaces: readers, checks, TetGen, generated meshes (fem/mesh_io.hpp,
# surface_io.hpp, tetrahedralize.hpp, mesh_vtk_series.hpp, cylinder_mesh.hpp, fem_box_mesh.hpp)
set(PLIANT_MESH_PARSER_SOURCES
  ${pliant_host_src}/mesh/mesh_check.cpp
  ${pliant_host_src}/mesh/mesh_msh.cpp
  ${pliant_host_src}/mesh/mesh_tetgen.cpp
  ${pliant_host_src}/mesh/surface_io.cpp
  ${pliant_host_src}/mesh/surface_check.cpp)
set(PLIANT_MESH_SOURCES ${PLIANT_MESH_PARSER_SOURCES}
  ${pliant_host_src}/mesh/mesh_read.cpp
  ${pliant_host_src}/mesh/tetrahedralize.cpp
  ${pliant_host_src}/mesh/mesh_vtk_series.cpp
  ${pliant_host_src}/mesh/cylinder_mesh.cpp
  ${pliant_host_src}/mesh/fem_box_mesh.cpp)
# corotational FEM: model, Cholesky, solvers, modal analysis, recordings as FEM problems,
# material maps (fem/fem_model.hpp, fem_solver.hpp, fem_modal.hpp, fem_recording.hpp, material_map.hpp)
set(PLIANT_FEM_SOURCES
  ${pliant_host_src}/fem/fem_model.cpp
  ${pliant_host_src}/fem/fem_cholesky.cpp
  ${pliant_host_src}/fem/fem_solver.cpp
  ${pliant_host_src}/fem/fem_modal.cpp
  ${pliant_host_src}/fem/fem_condensation.cpp
  ${pliant_host_src}/fem/fem_recording.cpp
  ${pliant_host_src}/fem/material_map.cpp)
# the one least-squares path, on Ceres (least_squares_fit.hpp)
set(PLIANT_FIT_SOURCES
  ${pliant_host_src}/fit/least_squares_fit.cpp)
# FEM material estimators: static, dynamic (trajectory), rest shape (fem/estimate_*.hpp)
set(PLIANT_FEM_ESTIMATION_SOURCES
  ${pliant_host_src}/fem_estimation/estimate_static.cpp
  ${pliant_host_src}/fem_estimation/estimate_dynamic.cpp
  ${pliant_host_src}/fem_estimation/estimate_dynamic_modal.cpp
  ${pliant_host_src}/fem_estimation/trajectory_sensitivity.cpp
  ${pliant_host_src}/fem_estimation/estimate_rest_shape.cpp
  ${pliant_host_src}/fem_estimation/material_map_selection.cpp)
# importers of outside datasets: compression tests (fem/compression_test.hpp)
set(PLIANT_DATASETS_SOURCES
  ${pliant_host_src}/datasets/compression_test_csv.cpp
  ${pliant_host_src}/datasets/compression_test_recording.cpp)
# scenario generators for simulate, tests and benchmarks (scenarios.hpp, fem/stepe_scenario.hpp,
# fem/bar_vibration_scenario.hpp)
set(PLIANT_TESTING_SOURCES
  ${pliant_host_src}/testing/scenarios.cpp
  ${pliant_host_src}/testing/scenario_effects.cpp
  ${pliant_host_src}/testing/stepe_scenario.cpp
  ${pliant_host_src}/testing/bar_vibration_scenario.cpp)
# missing-physics diagnosis (MSM and FEM baselines) and its HTML report (diagnose/*.hpp)
set(PLIANT_DIAGNOSIS_SOURCES
  ${pliant_host_src}/diagnose/noise_floor.cpp
  ${pliant_host_src}/diagnose/holdout.cpp
  ${pliant_host_src}/diagnose/residual_field.cpp
  ${pliant_host_src}/diagnose/locate.cpp
  ${pliant_host_src}/diagnose/model_run.cpp
  ${pliant_host_src}/diagnose/effects.cpp
  ${pliant_host_src}/diagnose/selection.cpp
  ${pliant_host_src}/diagnose/engine.cpp
  ${pliant_host_src}/diagnose/diagnose.cpp
  ${pliant_host_src}/diagnose/support_friction.cpp
  ${pliant_host_src}/diagnose/fem_model_run.cpp
  ${pliant_host_src}/diagnose/fem_effects.cpp
  ${pliant_host_src}/diagnose/fem_diagnose.cpp
  ${pliant_host_src}/diagnose/svg_plot.cpp
  ${pliant_host_src}/diagnose/html_report.cpp)
# telemetry: transports, the bridge's stream decoded, JSON lines, recordings (telemetry/*.hpp)
set(PLIANT_TELEMETRY_SOURCES
  ${pliant_host_src}/telemetry/fd_io.cpp
  ${pliant_host_src}/telemetry/serial_source.cpp
  ${pliant_host_src}/telemetry/udp_source.cpp
  ${pliant_host_src}/telemetry/file_source.cpp
  ${pliant_host_src}/telemetry/stream.cpp
  ${pliant_host_src}/telemetry/stream_summary.cpp
  ${pliant_host_src}/telemetry/json_lines.cpp
  ${pliant_host_src}/telemetry/recording_builder.cpp)
# a recording played through the HAL replay devices with the online estimate (replay/*.hpp)
set(PLIANT_REPLAY_SOURCES
  ${pliant_host_src}/replay/replay_channels.cpp
  ${pliant_host_src}/replay/online_estimator.cpp
  ${pliant_host_src}/replay/replay_session.cpp)
