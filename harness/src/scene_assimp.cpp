// The only file that includes assimp.
#include <filesystem>
#include <fstream>

#include <Eigen/Dense>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "error.h"
#include "input_file.h"
#include "ply_precheck.h"
#include "procedural.h"
#include "scene.h"

namespace raybench {
namespace {

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

Vec3f transform_point(const Eigen::Matrix4d& m, const aiVector3D& p) {
  const Eigen::Vector4d w = m * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
  return {static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
}

void collect(const aiScene& ai, const aiNode& node, const Eigen::Matrix4d& parent, Scene& out) {
  const Eigen::Matrix4d world = parent * to_eigen(node.mTransformation);
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& mesh = *ai.mMeshes[node.mMeshes[m]];
    if (mesh.mNumFaces == 0) out.skipped_points += mesh.mNumVertices;  // a point cloud stores bare vertices
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 1) { ++out.skipped_points; continue; }
      if (face.mNumIndices == 2) { ++out.skipped_lines; continue; }
      if (face.mNumIndices != 3) continue;  // aiProcess_Triangulate leaves none
      out.triangles.push_back({transform_point(world, mesh.mVertices[face.mIndices[0]]),
                               transform_point(world, mesh.mVertices[face.mIndices[1]]),
                               transform_point(world, mesh.mVertices[face.mIndices[2]])});
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) collect(ai, *node.mChildren[c], world, out);
}

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
  Assimp::Importer importer;
  // Triangulate only. No FindDegenerates/SortByPType: they turn the 52,670
  // coincident-vertex triangles of conference.ply into lines, and every
  // backend must see every triangle of the file. No JoinIdenticalVertices:
  // the triangle array does not need shared vertices.
  const aiScene* ai = importer.ReadFile(path, aiProcess_Triangulate);
  if (!ai) {
    std::string why = importer.GetErrorString();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    for (char& c : why) if (c == '\n') c = ' ';
    throw InputError(path, "cannot be read as a mesh (assimp: " + why + ")");
  }
  if (!ai->mRootNode) throw InputError(path, "the file has no scene graph");

  Scene scene;
  scene.source = path;
  scene.name = fs::path(path).stem().string();
  collect(*ai, *ai->mRootNode, Eigen::Matrix4d::Identity(), scene);
  if (scene.triangles.empty()) {
    throw InputError(path, "contains no triangles (" + std::to_string(scene.skipped_points) + " points, " +
                               std::to_string(scene.skipped_lines) + " lines): nothing to trace");  // e.g. a point cloud
  }
  return scene;
}

}  // namespace

Scene load_scene(const std::string& spec) {
  if (spec.rfind(kProceduralPrefix, 0) == 0) return make_procedural_scene(spec);
  return load_mesh_file(spec);
}

}  // namespace raybench
