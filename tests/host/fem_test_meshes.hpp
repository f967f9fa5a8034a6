// Test support for the FEM tests (also used by bench/fem_convergence.cpp): a minimal gmsh MSH 4.1
// ASCII reader (nodes in entity blocks, type-4 tetrahedra only), enough for the IPC meshes checked
// in under examples/meshes/tetmesh_ipc, deliberately independent of the library's mesh I/O; and
// the area share of the nodes of a planar boundary face (for traction loads and face averages).
#pragma once

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/recording.hpp"

#ifndef PLIANT_FEM_MESH_DIR
#error "PLIANT_FEM_MESH_DIR must name examples/meshes/tetmesh_ipc"
#endif

namespace pliant::host::test {

inline TetMesh read_msh41_tets(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open " + path);
  TetMesh mesh;
  std::unordered_map<long, int> index_of_tag;
  std::string token;
  while (file >> token) {
    if (token == "$MeshFormat") {
      std::string version;
      int binary = 0;
      int size = 0;
      file >> version >> binary >> size;
      if (version.rfind("4.1", 0) != 0 || binary != 0) throw std::runtime_error(path + ": not MSH 4.1 ASCII");
    } else if (token == "$Nodes") {
      long blocks = 0, count = 0, min_tag = 0, max_tag = 0;
      file >> blocks >> count >> min_tag >> max_tag;
      for (long b = 0; b < blocks; ++b) {
        int entity_dim = 0, entity_tag = 0, parametric = 0;
        long in_block = 0;
        file >> entity_dim >> entity_tag >> parametric >> in_block;
        if (parametric != 0) throw std::runtime_error(path + ": parametric nodes not supported");
        std::vector<long> tags(static_cast<std::size_t>(in_block));
        for (long& tag : tags) file >> tag;
        for (long tag : tags) {
          double x = 0, y = 0, z = 0;
          file >> x >> y >> z;
          index_of_tag[tag] = mesh.point_count();
          mesh.points.insert(mesh.points.end(), {x, y, z});
        }
      }
    } else if (token == "$Elements") {
      long blocks = 0, count = 0, min_tag = 0, max_tag = 0;
      file >> blocks >> count >> min_tag >> max_tag;
      for (long b = 0; b < blocks; ++b) {
        int entity_dim = 0, entity_tag = 0, type = 0;
        long in_block = 0;
        file >> entity_dim >> entity_tag >> type >> in_block;
        if (type != 4) throw std::runtime_error(path + ": only linear tetrahedra (type 4) supported");
        for (long e = 0; e < in_block; ++e) {
          long tag = 0;
          file >> tag;
          for (int a = 0; a < 4; ++a) {
            long node = 0;
            file >> node;
            const auto found = index_of_tag.find(node);
            if (found == index_of_tag.end()) throw std::runtime_error(path + ": unknown node tag");
            mesh.tetrahedra.push_back(found->second);
          }
        }
      }
    }
    if (!file) throw std::runtime_error(path + ": malformed");
  }
  if (mesh.points.empty() || mesh.tetrahedra.empty()) throw std::runtime_error(path + ": no nodes or tetrahedra");
  return mesh;
}

/// One of the checked-in IPC meshes by file name, e.g. "bar-2523.msh".
inline TetMesh ipc_mesh(const std::string& name) {
  return read_msh41_tets(std::string(PLIANT_FEM_MESH_DIR) + "/" + name);
}

/// Area share (m^2) of every node on the boundary plane {coordinate `axis` = value}: a third of
/// the area of each tetrahedron face lying in that plane. Sums to the face area. n entries.
inline std::vector<double> face_area_weights(const fem::FemModel& model, int axis, double value) {
  std::vector<double> weight(static_cast<std::size_t>(model.node_count()), 0.0);
  const Eigen::VectorXd& rest = model.rest_position_m();
  auto on_face = [&](int node) { return std::abs(rest[3 * node + axis] - value) < 1e-9; };
  constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& tet : model.elements()) {
    for (const auto& face : kFaces) {
      const int a = tet[static_cast<std::size_t>(face[0])];
      const int b = tet[static_cast<std::size_t>(face[1])];
      const int c = tet[static_cast<std::size_t>(face[2])];
      if (!on_face(a) || !on_face(b) || !on_face(c)) continue;
      const Eigen::Vector3d pa = rest.segment<3>(3 * a);
      const double area = 0.5 * (rest.segment<3>(3 * b) - pa).cross(rest.segment<3>(3 * c) - pa).norm();
      for (int node : {a, b, c}) weight[static_cast<std::size_t>(node)] += area / 3.0;
    }
  }
  return weight;
}

}  // namespace pliant::host::test
