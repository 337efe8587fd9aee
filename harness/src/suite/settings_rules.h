// The rules every numeric setting obeys, wherever it is given: the command
// line (`--rays 100`) and a suite manifest (`rays = 100` under [defaults])
// go through the same function, so a value refused in one place is refused in
// the other with the same words. A refused value throws InputError naming
// where it came from (the flag, or the manifest file and key) and what the
// setting accepts, before any scene is loaded.
//
// The maxima are sanity bounds, not capabilities: each is far above any run
// raybench is used for, and low enough that a typo (an extra digit, a
// negative number read as unsigned) fails at once instead of allocating for
// hours or running forever.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace raybench {

// A setting's value as the user gave it.
struct GivenValue {
  std::string where;                    // "--rays", or "suite.toml: 'defaults.rays'"
  std::string text;                     // as written, quoted in messages
  std::optional<std::int64_t> integer;  // set when it is an integer that fits int64
  std::optional<double> number;         // set when it is a number (an integer too)

  // A command-line value: `text` is parsed here (decimal integers; reals as strtod reads them).
  static GivenValue from_flag(std::string flag, std::string text);
  // A manifest value already typed by the TOML reader; `text` is its TOML spelling.
  static GivenValue from_manifest(const std::string& file, const std::string& key, std::string text,
                                  std::optional<std::int64_t> integer, std::optional<double> number);
};

inline constexpr std::int64_t kMaxRays = std::int64_t{1} << 28;        // rays per ray set: 8 GiB of rays
inline constexpr std::int64_t kMaxKernelRays = std::int64_t{1} << 24;  // accuracy-kernels: rays per ray set
inline constexpr std::int64_t kMaxThreads = 1024;
inline constexpr std::int64_t kMaxRepetitions = 1000;
inline constexpr std::int64_t kMinPairs = 8;  // one 8-wide batch
inline constexpr std::int64_t kMaxPairs = std::int64_t{1} << 24;
inline constexpr double kMaxSeconds = 3600.0;  // per repetition, or of warm-up

std::size_t rays_setting(const GivenValue& v);          // 1 .. kMaxRays
std::size_t kernel_rays_setting(const GivenValue& v);   // 1 .. kMaxKernelRays
int threads_setting(const GivenValue& v);               // 1 .. kMaxThreads
int repetitions_setting(const GivenValue& v);           // 1 .. kMaxRepetitions (timed repetitions)
int build_repetitions_setting(const GivenValue& v);     // 1 .. kMaxRepetitions (timed rounds of builds)
std::uint64_t seed_setting(const GivenValue& v);        // 0 .. 2^64 - 1
std::size_t pairs_setting(const GivenValue& v);         // kMinPairs .. kMaxPairs
double min_time_setting(const GivenValue& v);           // finite seconds in (0, kMaxSeconds]
double warmup_setting(const GivenValue& v);             // finite seconds in [0, kMaxSeconds]
double alpha_setting(const GivenValue& v);              // finite, in (0, 1)
double min_effect_setting(const GivenValue& v);         // finite, in [0, 10]
// The timing reference (--reference, [defaults] reference): a backend name as
// --backend takes it (not empty, no ',' or control character). Whether the
// run has that backend is checked when the run starts (timing_reference).
std::string reference_setting(const GivenValue& v);
// The memory policy (--huge-pages, [defaults] huge_pages): "on" (every
// backend's acceleration structure in transparent huge pages) or "off".
bool huge_pages_setting(const GivenValue& v);

// Why `name` cannot name a scene, or "" when it can. A scene's name becomes
// part of file names in --rays-dir and a field of the results CSV, and is
// selected with --scene a,b: so no path separator ('/' or '\'), no control
// character (a newline would split the CSV row), no comma, not empty.
std::string scene_name_problem(std::string_view name);

// `text` with every control character written as \xNN, for an error message
// that must stay one line whatever the user's file name holds.
std::string printable(std::string_view text);

}  // namespace raybench
