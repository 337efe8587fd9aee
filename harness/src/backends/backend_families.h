// The backend families the registry knows. Each family lives in one file of
// this folder; adding a family is one factory here and one line in
// backend_registry.cpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "backends/backend.h"

namespace raybench {

std::unique_ptr<Backend> make_embree_backend(const std::string& name, const std::vector<std::string>& options,
                                             const BackendConfig& config);
std::vector<BackendInfo> embree_backend_names();
std::string embree_version();

std::unique_ptr<Backend> make_bvh2_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig& config);
std::vector<BackendInfo> bvh2_backend_names();

std::unique_ptr<Backend> make_bvh8_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig& config);
std::vector<BackendInfo> bvh8_backend_names();
std::unique_ptr<Backend> make_bvh4_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig& config);
std::vector<BackendInfo> bvh4_backend_names();

std::unique_ptr<Backend> make_reference_backend(const std::string& name, const std::vector<std::string>& options,
                                                const BackendConfig& config);
std::vector<BackendInfo> reference_backend_names();

}  // namespace raybench
