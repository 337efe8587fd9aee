// A plugin library (raybench/plugin.h) loaded into the process, its table
// checked once, and the rule that splits a backend name "plugin:PATH[:options]".
// Guarantee: load_plugin_library returns only a library whose table speaks
// this raybench's ABI version and has every required function and string;
// every other case is an InputError of one line naming the file. A library
// is loaded once per process (per canonical path) and never unloaded, so
// the table's pointers and strings stay valid until the process ends.
#pragma once

#include <string>

#include "raybench/plugin.h"

namespace raybench {

// The accuracy classes a plugin may report (plugin.h): fast, epsilon,
// watertight, exact.
bool is_plugin_accuracy_class(const std::string& accuracy_class);

// "plugin:PATH[:options]" split: PATH ends at the first ':' that follows
// ".so", ".dylib" or ".dll" (so a folder name may contain ':' and '.'), and
// the options are everything after that ':' (they may contain ':'). Without
// such a ':', PATH is the whole rest of the name and there are no options.
struct PluginName {
  std::string path;
  std::string options;
};
// Throws InputError for a name that does not start with "plugin:" or names
// no PATH.
PluginName split_plugin_name(const std::string& backend_name);

struct PluginLibrary {
  std::string path;     // absolute and canonical, as loaded
  std::string sha256;   // of the file's bytes when it was loaded, lower-case hex
  const raybench_plugin_table* table = nullptr;
  std::string name;         // table->name
  std::string description;  // table->description ("" when NULL)
  std::string accuracy_class;
};

// Loads the library at `path` (relative to the working directory; never
// searched for on the library path) with dlopen(RTLD_NOW | RTLD_LOCAL),
// calls its entry point and checks the table. Thread-safe; later calls for
// the same file return the same object. `backend_name` only names the
// backend in errors.
const PluginLibrary& load_plugin_library(const std::string& path, const std::string& backend_name);

// SHA-256 of a file's bytes, lower-case hex. Throws InputError when it
// cannot be read.
std::string sha256_of_file(const std::string& path);
// SHA-256 of bytes, lower-case hex (FIPS 180-4).
std::string sha256_hex(const void* data, std::size_t size);

}  // namespace raybench
