// Screening of a ray set (rays/screening.h).
#include "rays/screening.h"

#include <stdexcept>

namespace raybench {

ScreenedRays screen_rays(std::span<const Ray> rays) {
  ScreenedRays out;
  out.rays.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!is_traceable(rays[i])) {
      out.rays[i] = kEmptyRay;
      out.screened.push_back(i);
      continue;
    }
    out.rays[i] = with_nonnegative_tnear(rays[i]);
    out.raised_tnear += rays[i].tnear < 0.0f;
  }
  return out;
}

namespace {

template <typename T>
void force(const ScreenedRays& screened, std::span<T> answers, const T& miss) {
  if (answers.size() != screened.rays.size())
    throw std::logic_error("force_misses: the answers are not those of the screened rays");
  for (const std::size_t i : screened.screened) answers[i] = miss;
}

}  // namespace

void force_misses(const ScreenedRays& screened, std::span<Hit> answers) { force(screened, answers, Hit{}); }

void force_misses(const ScreenedRays& screened, std::span<std::uint8_t> answers) {
  force(screened, answers, std::uint8_t{0});
}

}  // namespace raybench
