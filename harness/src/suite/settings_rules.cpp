#include "suite/settings_rules.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>

#include "io/error.h"

namespace raybench {
namespace {

[[noreturn]] void refuse(const GivenValue& v, const std::string& rule) {
  throw InputError(v.where, fmt::format("must be {}, got {}", rule, v.text.empty() ? "nothing" : v.text));
}

std::int64_t integer_in(const GivenValue& v, std::int64_t min, std::int64_t max, const char* what = "an integer") {
  const std::string rule = fmt::format("{} from {} to {}", what, min, max);
  if (!v.integer || *v.integer < min || *v.integer > max) refuse(v, rule);
  return *v.integer;
}

// A finite number in [min, max], or in (min, max] when min is excluded.
double number_in(const GivenValue& v, double min, bool min_excluded, double max, bool max_excluded, const char* what) {
  const std::string rule =
      fmt::format("{} in {}{}, {}{}", what, min_excluded ? "(" : "[", min, max, max_excluded ? ")" : "]");
  if (!v.number || !std::isfinite(*v.number)) refuse(v, rule);
  const double x = *v.number;
  if (x < min || (min_excluded && x == min) || x > max || (max_excluded && x == max)) refuse(v, rule);
  return x;
}

}  // namespace

GivenValue GivenValue::from_flag(std::string flag, std::string text) {
  GivenValue v;
  v.where = std::move(flag);
  v.text = std::move(text);
  const char* begin = v.text.data();
  const char* end = begin + v.text.size();
  std::int64_t i = 0;
  if (const auto [p, ec] = std::from_chars(begin, end, i); ec == std::errc() && p == end) {
    v.integer = i;
    v.number = static_cast<double>(i);
    return v;
  }
  // strtod: decimal and hexadecimal reals, "inf" and "nan" (refused by the
  // rules that need a finite value, with the value named); no leading space.
  if (!v.text.empty() && !std::isspace(static_cast<unsigned char>(v.text.front()))) {
    char* stop = nullptr;
    const double d = std::strtod(begin, &stop);
    if (stop == end) v.number = d;
  }
  return v;
}

GivenValue GivenValue::from_manifest(const std::string& file, const std::string& key, std::string text,
                                     std::optional<std::int64_t> integer, std::optional<double> number) {
  GivenValue v;
  v.where = fmt::format("{}: '{}'", file, key);
  v.text = std::move(text);
  v.integer = integer;
  v.number = number;
  return v;
}

std::size_t rays_setting(const GivenValue& v) { return static_cast<std::size_t>(integer_in(v, 1, kMaxRays)); }

std::size_t kernel_rays_setting(const GivenValue& v) {
  return static_cast<std::size_t>(integer_in(v, 1, kMaxKernelRays));
}

int threads_setting(const GivenValue& v) { return static_cast<int>(integer_in(v, 1, kMaxThreads)); }

int repetitions_setting(const GivenValue& v) { return static_cast<int>(integer_in(v, 1, kMaxRepetitions)); }

int build_repetitions_setting(const GivenValue& v) { return static_cast<int>(integer_in(v, 1, kMaxRepetitions)); }

std::uint64_t seed_setting(const GivenValue& v) {
  const std::string rule = fmt::format("an integer from 0 to {}", std::numeric_limits<std::uint64_t>::max());
  if (v.integer) {
    if (*v.integer < 0) refuse(v, rule);
    return static_cast<std::uint64_t>(*v.integer);
  }
  // Seeds above 2^63 - 1 can only come from the command line (TOML integers are int64).
  std::uint64_t u = 0;
  const char* end = v.text.data() + v.text.size();
  if (const auto [p, ec] = std::from_chars(v.text.data(), end, u); ec == std::errc() && p == end) return u;
  refuse(v, rule);
}

std::size_t pairs_setting(const GivenValue& v) { return static_cast<std::size_t>(integer_in(v, kMinPairs, kMaxPairs)); }

double min_time_setting(const GivenValue& v) {
  return number_in(v, 0.0, true, kMaxSeconds, false, "a finite number of seconds");
}

double warmup_setting(const GivenValue& v) {
  return number_in(v, 0.0, false, kMaxSeconds, false, "a finite number of seconds");
}

double alpha_setting(const GivenValue& v) { return number_in(v, 0.0, true, 1.0, true, "a significance level"); }

double min_effect_setting(const GivenValue& v) { return number_in(v, 0.0, false, 10.0, false, "a relative change"); }

std::string reference_setting(const GivenValue& v) {
  const std::string rule = "one of the run's backend names, e.g. embree";
  if (v.text.empty()) refuse(v, rule);
  for (const char c : v.text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f || c == ',') refuse(v, rule + " (one name, no ',' or control character)");
  }
  return v.text;
}

bool huge_pages_setting(const GivenValue& v) {
  if (v.text == "on") return true;
  if (v.text == "off") return false;
  refuse(v, "on or off");
}

std::string scene_name_problem(std::string_view name) {
  if (name.empty()) return "a scene name must not be empty";
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f)
      return fmt::format("a scene name must not contain control characters (found {:#04x}): it is a field of the results CSV", u);
    if (c == '/' || c == '\\')
      return fmt::format("a scene name must not contain '{}': it names the scene's ray files in --rays-dir", c);
    if (c == ',') return "a scene name must not contain ',': --scene a,b could not select it";
  }
  return "";
}

std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    out += u < 0x20 || u == 0x7f ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  return out;
}

}  // namespace raybench
