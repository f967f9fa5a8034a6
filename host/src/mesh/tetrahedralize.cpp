// Constrained Delaunay tetrahedralization of a closed surface through TetGen 1.5's library API.
//
// TETLIBRARY must be defined before tetgen.h: Debian's libtet is built with it, so the header's
// inline terminatetetgen() throws the error code (an int) instead of calling exit(), and the
// char* overload of tetrahedralize() is declared.
//
// TetGen 1.5.0 runs in a child process. When it detects an error in the input (a
// self-intersection, say) it frees its mesh and throws, and then the destructor of the mesh
// inside tetrahedralize() frees the same memory again: the process crashes during unwinding,
// before any catch runs. A child process contains that crash (and TetGen's printing, its global
// state and any runaway refinement, see timeout_s) and the caller gets a MeshError. The child
// writes its result to an unlinked temporary file, so nothing can block on a full pipe.
#define TETLIBRARY
#include <tetgen.h>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/tetrahedralize.hpp"

namespace pliant::host {
namespace {

using mesh_detail::fail_file;

// Fixed notation (TetGen's switch parser reads digits and '.'), shortest that reads back.
std::string fixed_number(double value) {
  char buffer[512];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  if (result.ec != std::errc()) return std::string();
  return std::string(buffer, result.ptr);
}

std::string tetgen_failure(std::int64_t code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error";
    case 3: return "the surface intersects itself (TetGen found a self-intersection)";
    case 4: return "the surface has a feature smaller than TetGen's tolerance";
    case 5: return "two facets of the surface are very close or overlap";
    case 10: return "TetGen rejected the input or the switches";
    default: break;
  }
  return "TetGen failed with error code " + std::to_string(code);
}

// An anonymous temporary file (tmpfile(3)), shared with the child through fork.
class TempFile {
 public:
  explicit TempFile(const std::string& label) : file_(std::tmpfile()) {
    if (file_ == nullptr) {
      fail_file(label, std::string("cannot create a temporary file for TetGen: ") + std::strerror(errno));
    }
  }
  ~TempFile() { std::fclose(file_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  int fd() const { return fileno(file_); }

  std::string read_all() const {
    std::string out;
    if (lseek(fd(), 0, SEEK_SET) != 0) return out;
    char buffer[65536];
    for (;;) {
      const ssize_t n = ::read(fd(), buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      out.append(buffer, static_cast<std::size_t>(n));
    }
    return out;
  }

 private:
  std::FILE* file_;
};

bool write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Result file layout (native byte order, same machine): 5 int64 (code, points, tets, corners,
// first number), then 3 * points doubles, then corners * tets int32.
struct Result {
  std::int64_t code = 0;
  std::int64_t points = 0;
  std::int64_t tets = 0;
  std::int64_t corners = 0;
  std::int64_t first = 0;
  std::vector<double> coordinates;
  std::vector<std::int32_t> indices;
};

bool write_header(int fd, std::int64_t code, std::int64_t points, std::int64_t tets, std::int64_t corners,
                  std::int64_t first) {
  const std::int64_t header[5] = {code, points, tets, corners, first};
  return write_all(fd, header, sizeof header);
}

// Runs in the child process. Returns its exit status: 0 when the result file is complete.
int run_tetgen(const TriangleSurface& surface, const std::string& switches, int data_fd) {
  try {
    const std::size_t point_count = surface.points.size() / 3;
    const std::size_t triangle_count = surface.triangles.size() / 3;
    tetgenio in;
    tetgenio out;
    in.firstnumber = 0;
    in.numberofpoints = static_cast<int>(point_count);
    in.pointlist = new REAL[surface.points.size()];
    for (std::size_t i = 0; i < surface.points.size(); ++i) in.pointlist[i] = surface.points[i];
    // numberoffacets counts only complete facets, so that tetgenio's destructor frees exactly
    // what was allocated if an allocation below throws.
    in.facetlist = new tetgenio::facet[triangle_count];
    in.numberoffacets = 0;
    for (std::size_t t = 0; t < triangle_count; ++t) {
      tetgenio::facet& facet = in.facetlist[t];
      facet.numberofholes = 0;
      facet.holelist = nullptr;
      facet.numberofpolygons = 0;
      facet.polygonlist = new tetgenio::polygon[1];
      facet.polygonlist[0].numberofvertices = 0;
      facet.polygonlist[0].vertexlist = nullptr;
      facet.numberofpolygons = 1;
      ++in.numberoffacets;
      facet.polygonlist[0].vertexlist = new int[3];
      facet.polygonlist[0].numberofvertices = 3;
      for (std::size_t k = 0; k < 3; ++k) {
        facet.polygonlist[0].vertexlist[k] = surface.triangles[3 * t + k];
      }
    }
    std::vector<char> command(switches.begin(), switches.end());
    command.push_back('\0');
    tetrahedralize(command.data(), &in, &out);

    const std::int64_t points = out.pointlist != nullptr ? out.numberofpoints : 0;
    const std::int64_t tets = out.tetrahedronlist != nullptr ? out.numberoftetrahedra : 0;
    const std::int64_t corners = out.numberofcorners;
    if (points < 0 || tets < 0 || corners < 0) return 3;
    bool ok = write_header(data_fd, 0, points, tets, corners, out.firstnumber);
    if (points > 0) {
      ok = ok && write_all(data_fd, out.pointlist, 3 * static_cast<std::size_t>(points) * sizeof(REAL));
    }
    if (tets > 0) {
      ok = ok && write_all(data_fd, out.tetrahedronlist, static_cast<std::size_t>(corners * tets) * sizeof(int));
    }
    return ok ? 0 : 4;
  } catch (const int code) {
    // Reached only when TetGen fails before building its mesh (bad switches); see the top.
    return write_header(data_fd, code == 0 ? -1 : code, 0, 0, 0, 0) ? 0 : 4;
  } catch (const std::bad_alloc&) {
    return write_header(data_fd, 1, 0, 0, 0, 0) ? 0 : 4;
  } catch (...) {
    return 5;
  }
}

bool read_result(const std::string& bytes, Result& result) {
  static_assert(sizeof(REAL) == sizeof(double) && sizeof(int) == sizeof(std::int32_t),
                "TetGen built with REAL = double and 32-bit int");
  std::int64_t header[5];
  if (bytes.size() < sizeof header) return false;
  std::memcpy(header, bytes.data(), sizeof header);
  result.code = header[0];
  result.points = header[1];
  result.tets = header[2];
  result.corners = header[3];
  result.first = header[4];
  if (result.points < 0 || result.tets < 0 || result.corners < 0 || result.corners > 10 ||
      result.points > (std::int64_t{1} << 40) || result.tets > (std::int64_t{1} << 40)) {
    return false;
  }
  const auto coordinates = 3 * static_cast<std::size_t>(result.points);
  const auto indices = static_cast<std::size_t>(result.corners * result.tets);
  if (bytes.size() != sizeof header + coordinates * sizeof(double) + indices * sizeof(std::int32_t)) {
    return false;
  }
  result.coordinates.resize(coordinates);
  result.indices.resize(indices);
  if (coordinates > 0) {
    std::memcpy(result.coordinates.data(), bytes.data() + sizeof header, coordinates * sizeof(double));
  }
  if (indices > 0) {
    std::memcpy(result.indices.data(), bytes.data() + sizeof header + coordinates * sizeof(double),
                indices * sizeof(std::int32_t));
  }
  return true;
}

// " (TetGen: <its last lines>)" from what the child printed, or "".
std::string tetgen_said(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    std::string line = text.substr(start, stop - start);
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos) {
      line = line.substr(first);
      while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
      // Sanitizer reports are long and name no input problem.
      if (line.rfind("==", 0) != 0) lines.push_back(line);
    }
    start = stop + 1;
  }
  if (lines.empty()) return std::string();
  std::string joined;
  const std::size_t from = lines.size() > 3 ? lines.size() - 3 : 0;
  for (std::size_t i = from; i < lines.size(); ++i) {
    if (!joined.empty()) joined += " / ";
    joined += lines[i];
  }
  return " (TetGen: " + mesh_detail::printable(joined, 240) + ")";
}

TetMesh to_mesh(const Result& result, const std::string& label) {
  if (result.tets <= 0 || result.points <= 0) fail_file(label, "TetGen produced no tetrahedra");
  if (result.corners != 4) {
    fail_file(label, "TetGen produced " + std::to_string(result.corners) + "-node tetrahedra, expected 4");
  }
  const auto out_points = static_cast<std::size_t>(result.points);
  // Keep the points the tetrahedra use, in TetGen's order (input points first).
  std::vector<int> new_index(out_points, -1);
  for (const std::int32_t raw : result.indices) {
    const std::int64_t index = static_cast<std::int64_t>(raw) - result.first;
    if (index < 0 || static_cast<std::size_t>(index) >= out_points) {
      fail_file(label, "TetGen returned a point index out of range");
    }
    new_index[static_cast<std::size_t>(index)] = 0;
  }
  TetMesh mesh;
  int next = 0;
  for (std::size_t i = 0; i < out_points; ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = next++;
    mesh.points.insert(mesh.points.end(), result.coordinates.begin() + static_cast<std::ptrdiff_t>(3 * i),
                       result.coordinates.begin() + static_cast<std::ptrdiff_t>(3 * i + 3));
  }
  mesh.tetrahedra.reserve(result.indices.size());
  for (const std::int32_t raw : result.indices) {
    mesh.tetrahedra.push_back(new_index[static_cast<std::size_t>(static_cast<std::int64_t>(raw) - result.first)]);
  }
  // TetGen already writes positively oriented tetrahedra (checked with TetGen 1.5.0); this is
  // the contract every reader enforces, kept in case another TetGen build differs.
  orient_and_check_tet_mesh(mesh, label);
  return mesh;
}

}  // namespace

std::string tetgen_switches(const TetrahedralizeOptions& options) {
  const char* const label = "tetrahedralize options";
  std::string switches = "pz";
  if (options.quiet) switches += 'Q';
  if (options.preserve_surface) switches += 'Y';
  const double ratio = options.max_radius_edge_ratio;
  const double angle = options.min_dihedral_angle_deg;
  if (!(ratio == 0.0 || (ratio >= 1.0 && ratio <= 1e6))) {
    fail_file(label, "max_radius_edge_ratio must be 0 (off) or in [1, 1e6]");
  }
  if (!(angle >= 0.0 && angle < 70.0)) {
    fail_file(label, "min_dihedral_angle_deg must be in [0, 70)");
  }
  if (angle > 0.0 && ratio == 0.0) {
    fail_file(label, "min_dihedral_angle_deg needs quality refinement (max_radius_edge_ratio > 0)");
  }
  if (ratio > 0.0) {
    switches += 'q' + fixed_number(ratio);
    if (angle > 0.0) switches += '/' + fixed_number(angle);
  }
  const double volume = options.max_tet_volume;
  if (!(volume == 0.0 || (volume >= 1e-30 && volume <= 1e30))) {
    fail_file(label, "max_tet_volume must be 0 (unbounded) or in [1e-30, 1e30]");
  }
  if (volume > 0.0) switches += 'a' + fixed_number(volume);
  return switches;
}

TetMesh tetrahedralize(const TriangleSurface& surface, const TetrahedralizeOptions& options,
                       const std::string& file_label) {
  require_closed_surface(surface, file_label);
  const std::string switches = tetgen_switches(options);
  if (!(options.timeout_s >= 0.0 && options.timeout_s <= 1e6)) {
    fail_file("tetrahedralize options", "timeout_s must be in [0, 1e6]");
  }
  TempFile data(file_label);
  TempFile messages(file_label);
  // Whatever this process has buffered must not be written a second time by the child.
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0) fail_file(file_label, std::string("cannot start TetGen: ") + std::strerror(errno));
  if (child == 0) {
    // The child: TetGen's output goes to `messages`, its result to `data`; never returns.
    dup2(messages.fd(), STDOUT_FILENO);
    dup2(messages.fd(), STDERR_FILENO);
    if (options.timeout_s > 0.0) alarm(static_cast<unsigned>(std::ceil(options.timeout_s)));
    const int status = run_tetgen(surface, switches, data.fd());
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(status);
  }
  int wait_status = 0;
  pid_t waited = -1;
  do {
    waited = waitpid(child, &wait_status, 0);
  } while (waited < 0 && errno == EINTR);
  const bool exited_cleanly = waited == child && WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0;

  Result result;
  const bool complete = read_result(data.read_all(), result);
  if (exited_cleanly && complete && result.code != 0) {
    fail_file(file_label, tetgen_failure(result.code) + tetgen_said(messages.read_all()));
  }
  if (!complete || !(exited_cleanly || waited < 0)) {
    std::string how = "stopped";
    if (waited == child && WIFSIGNALED(wait_status)) {
      how = WTERMSIG(wait_status) == SIGALRM
                ? "did not finish within timeout_s = " + fixed_number(options.timeout_s) + " s"
                : "crashed (signal " + std::to_string(WTERMSIG(wait_status)) + ")";
    } else if (waited == child && WIFEXITED(wait_status)) {
      how = "stopped (exit status " + std::to_string(WEXITSTATUS(wait_status)) + ")";
    }
    fail_file(file_label, "TetGen " + how +
                              " on this surface; usual causes: the surface intersects itself, two "
                              "facets nearly overlap, or a feature is below TetGen's tolerance" +
                              tetgen_said(messages.read_all()));
  }
  return to_mesh(result, file_label);
}

}  // namespace pliant::host
