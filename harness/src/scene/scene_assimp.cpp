// The only file that includes assimp. The import runs in a child process
// (isolated_call.h): Debian builds assimp with assertions, so a PLY or OFF
// cut mid-file aborts in its triangulation step, and it may read out of
// bounds or loop forever on other malformed files. The child imports,
// validates what assimp returns (every pointer and index, every vertex
// finite) and streams the flat triangle array through a pipe; a crash,
// non-zero exit or missed deadline of the child becomes one InputError
// naming the file. The child uses assimp, malloc and write(2) only, no TBB.
//
// The deadline is RAYBENCH_LOAD_TIMEOUT seconds (any number in (0, 86400],
// e.g. 0.5), 120 by default: room for any real mesh (a 28M-triangle one
// would take about 20 s), and a file that hangs assimp costs two minutes,
// not forever. measured: docs/notes/harness-measurement.md; what the
// isolation costs in load time: docs/reliability.md.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string_view>

#include <unistd.h>

#include <Eigen/Dense>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "io/error.h"
#include "io/input_file.h"
#include "scene/isolated_call.h"
#include "scene/ply_precheck.h"
#include "scene/procedural.h"
#include "scene/scene.h"

namespace raybench {
namespace {

constexpr double kDefaultLoadTimeoutSeconds = 120.0;
constexpr const char* kLoadTimeoutVariable = "RAYBENCH_LOAD_TIMEOUT";

// The child's answer on the pipe: kMesh, then the triangle count, skipped
// points and skipped lines as uint64, then the triangles' floats; or kError
// and a message. Both ends are this binary, so native byte order.
constexpr char kMesh = 'M';
constexpr char kError = 'E';

double load_timeout_seconds() {
  const char* text = std::getenv(kLoadTimeoutVariable);
  if (!text) return kDefaultLoadTimeoutSeconds;
  char* end = nullptr;
  errno = 0;
  const double seconds = std::strtod(text, &end);
  // Beyond a day, std::chrono's milliseconds would still hold it, but no
  // one means that: refused as a typo rather than waited for.
  if (end == text || *end != '\0' || errno != 0 || !(seconds > 0.0 && seconds <= 86400.0))
    throw InputError(kLoadTimeoutVariable, std::string("must be a number of seconds in (0, 86400], not '") + text + "'");
  return seconds;
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

// What the walk below collects, in the child.
struct Collected {
  std::vector<Triangle> triangles;
  std::uint64_t skipped_points = 0;
  std::uint64_t skipped_lines = 0;
  std::string problem;  // the first malformation found; the walk stops there
};

// Walks assimp's scene as scene.h documents, checking every pointer and
// index before it is followed (assimp's readers do not: a PLY face index
// out of range or negative is passed through), and every transformed vertex
// finite. Returns false, with `out.problem` set, at the first malformation.
bool collect(const aiScene& ai, const aiNode& node, const Eigen::Matrix4d& parent, Collected& out) {
  const Eigen::Matrix4d world = parent * to_eigen(node.mTransformation);
  const auto fail = [&](std::string problem) {
    out.problem = "malformed mesh: " + std::move(problem);
    return false;
  };
  if (node.mNumMeshes > 0 && !node.mMeshes) return fail("a node lists meshes but has no mesh array");
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const unsigned index = node.mMeshes[m];
    if (index >= ai.mNumMeshes || !ai.mMeshes || !ai.mMeshes[index])
      return fail("a node refers to mesh " + std::to_string(index) + " of " + std::to_string(ai.mNumMeshes));
    const aiMesh& mesh = *ai.mMeshes[index];
    const std::string which = "mesh " + std::to_string(index);
    if (mesh.mNumVertices > 0 && !mesh.mVertices) return fail(which + " has no vertex array");
    if (mesh.mNumFaces > 0 && !mesh.mFaces) return fail(which + " has no face array");
    if (mesh.mNumFaces == 0) out.skipped_points += mesh.mNumVertices;  // a point cloud stores bare vertices
    const auto vertex = [&](unsigned i) {
      const aiVector3D& p = mesh.mVertices[i];
      const Eigen::Vector4d w = world * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
      return Vec3f{static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
    };
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices > 0 && !face.mIndices) return fail("face " + std::to_string(f) + " of " + which + " has no indices");
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= mesh.mNumVertices) {
          // A negative index in the file reads as a large unsigned one: shown as the file has it.
          const auto as_signed = static_cast<std::int32_t>(face.mIndices[k]);
          return fail("face " + std::to_string(f) + " of " + which + " uses vertex " +
                      (as_signed < 0 ? std::to_string(as_signed) : std::to_string(face.mIndices[k])) +
                      ", but the mesh has " + std::to_string(mesh.mNumVertices) + " vertices");
        }
      }
      if (face.mNumIndices == 1) { ++out.skipped_points; continue; }
      if (face.mNumIndices == 2) { ++out.skipped_lines; continue; }
      if (face.mNumIndices != 3) continue;  // aiProcess_Triangulate leaves none
      const Triangle t{vertex(face.mIndices[0]), vertex(face.mIndices[1]), vertex(face.mIndices[2])};
      for (const Vec3f& v : {t.v0, t.v1, t.v2}) {
        if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)))
          return fail("face " + std::to_string(f) + " of " + which +
                      " has a vertex that is not a finite float once the node transforms are applied");
      }
      out.triangles.push_back(t);
    }
  }
  if (node.mNumChildren > 0 && !node.mChildren) return fail("a node lists children but has no child array");
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    if (!node.mChildren[c]) return fail("a node's child " + std::to_string(c) + " is missing");
    if (!collect(ai, *node.mChildren[c], world, out)) return false;
  }
  return true;
}

// In the child: imports, validates and sends the answer on `fd`.
void import_in_child(const std::string& path, int fd) {
  const auto send_error = [&](const std::string& message) {
    write_all(fd, &kError, 1);
    write_all(fd, message.data(), message.size());
  };
  Assimp::Importer importer;
  // Triangulate only. No FindDegenerates/SortByPType: they turn the 52,670
  // coincident-vertex triangles of conference.ply into lines, and every
  // backend must see every triangle of the file. No JoinIdenticalVertices:
  // the triangle array does not need shared vertices.
  const aiScene* ai = importer.ReadFile(path, aiProcess_Triangulate);
  if (!ai) {
    std::string why = importer.GetErrorString();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    for (char& c : why) if (c == '\n' || c == '\r') c = ' ';
    return send_error("cannot be read as a mesh (assimp: " + why + ")");
  }
  if (!ai->mRootNode) return send_error("the file has no scene graph");
  Collected got;
  if (!collect(*ai, *ai->mRootNode, Eigen::Matrix4d::Identity(), got)) return send_error(got.problem);
  const std::uint64_t counts[3] = {got.triangles.size(), got.skipped_points, got.skipped_lines};
  const bool sent = write_all(fd, &kMesh, 1) && write_all(fd, counts, sizeof counts) &&
                    write_all(fd, got.triangles.data(), got.triangles.size() * sizeof(Triangle));
  // Exits at once: freeing assimp's scene and the triangles, which the
  // exit discards anyway, kept the parent waiting (Sponza: tens of ms).
  ::_exit(sent ? 0 : 1);
}

// In the parent: the child's answer, decoded as it arrives, the triangles
// copied once, straight into the scene's array.
class Answer {
 public:
  explicit Answer(std::string path) : path_(std::move(path)) {}

  void receive(std::string_view chunk) {
    if (head_.empty() && !chunk.empty()) {
      head_.push_back(chunk.front());
      chunk.remove_prefix(1);
    }
    if (head_.empty()) return;
    if (head_[0] == kError) {
      head_.append(chunk.substr(0, std::min<std::size_t>(chunk.size(), 4096)));
      return;
    }
    if (head_[0] != kMesh) throw InputError(path_, "assimp's reader process sent something other than a mesh");
    if (head_.size() < kMeshHeader) {
      const std::size_t take = std::min(chunk.size(), kMeshHeader - head_.size());
      head_.append(chunk.substr(0, take));
      chunk.remove_prefix(take);
      if (head_.size() < kMeshHeader) return;
      std::memcpy(counts_, head_.data() + 1, sizeof counts_);
      if (counts_[0] > scene_.triangles.max_size())
        throw InputError(path_, "assimp's reader process announced " + std::to_string(counts_[0]) + " triangles");
      scene_.triangles.resize(counts_[0]);
    }
    const std::size_t room = scene_.triangles.size() * sizeof(Triangle) - received_;
    if (chunk.size() > room) throw InputError(path_, "assimp's reader process sent more than the mesh it announced");
    if (chunk.empty()) return;  // a mesh of no triangles has no data() to copy to (null: memcpy's undefined behaviour)
    std::memcpy(reinterpret_cast<char*>(scene_.triangles.data()) + received_, chunk.data(), chunk.size());
    received_ += chunk.size();
  }

  // Once the child has exited with status 0: the scene, or the error it sent.
  Scene finish() {
    if (!head_.empty() && head_[0] == kError) throw InputError(path_, head_.substr(1));
    if (head_.size() < kMeshHeader || received_ != scene_.triangles.size() * sizeof(Triangle))
      throw InputError(path_, "assimp's reader process ended without sending the whole mesh");
    scene_.skipped_points = counts_[1];
    scene_.skipped_lines = counts_[2];
    return std::move(scene_);
  }

 private:
  static constexpr std::size_t kMeshHeader = 1 + 3 * sizeof(std::uint64_t);
  std::string path_;
  std::string head_;  // the tag, then the counts or the error message
  std::uint64_t counts_[3] = {};
  Scene scene_;
  std::size_t received_ = 0;  // bytes of triangles
};

// Refuses, before assimp sees it, a PLY file whose header would hang assimp.
void check_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(kPlyPrecheckBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (const std::string problem = ply_header_problem(head); !problem.empty()) throw InputError(path, problem);
}

Scene load_mesh_file(const std::string& path) {
  namespace fs = std::filesystem;
  check_input_file(path, "mesh file");
  if (!std::ifstream(path).good()) throw InputError(path, "cannot be opened for reading");
  check_ply_header(path);

  const double timeout = load_timeout_seconds();
  Answer answer(path);
  try {
    run_isolated([&](int fd) { import_in_child(path, fd); },
                 std::chrono::milliseconds(static_cast<std::int64_t>(std::ceil(timeout * 1000.0))),
                 [&](std::string_view chunk) { answer.receive(chunk); });
  } catch (const IsolatedCallFailed& e) {
    // What assimp printed last, e.g. "ai_assert failure in ... : numOut != pMesh->mNumFaces".
    const std::string said = e.said().empty() ? "" : " (assimp printed: " + e.said() + ")";
    switch (e.kind()) {
      case IsolatedCallFailed::Kind::kSignal:
        throw InputError(path, "assimp crashed (" + signal_name(e.detail()) +
                                   ") reading this file: it is malformed or truncated" + said);
      case IsolatedCallFailed::Kind::kDeadline:
        throw InputError(path, "assimp did not finish reading it within " + seconds_text(timeout) + " s (" +
                                   kLoadTimeoutVariable + " sets this limit)" + said);
      case IsolatedCallFailed::Kind::kExit:
        throw InputError(path, "assimp's reader process failed (exit status " + std::to_string(e.detail()) + ")" + said);
    }
  }

  Scene scene = answer.finish();
  scene.source = path;
  scene.name = fs::path(path).stem().string();
  if (scene.triangles.empty()) {
    throw InputError(path, "contains no triangles (" + std::to_string(scene.skipped_points) + " points, " +
                               std::to_string(scene.skipped_lines) + " lines): nothing to trace");  // e.g. a point cloud
  }
  return scene;
}

}  // namespace

Scene load_scene(const std::string& spec) {
  Scene scene = spec.rfind(kProceduralPrefix, 0) == 0 ? make_procedural_scene(spec) : load_mesh_file(spec);
  check_scene_coordinates(scene, spec);
  return scene;
}

}  // namespace raybench
