// The tables a run prints at its end: per scene, speed relative to the run's
// timing reference and agreement with Embree (every run), then the exact
// referee's verdicts (--accuracy runs), with the two warnings a newcomer
// would otherwise miss: a case whose repetitions spread widely, and a camera
// that sees little of its scene.
#pragma once

#include <string>
#include <vector>

#include "accuracy/accuracy_csv.h"
#include "results/results_csv.h"

namespace raybench {

// A case's repetitions spread widely when the fastest is more than this
// times the slowest: its median is then not a number to trust (a noisy
// neighbour, frequency scaling, or a --min-time too short for the timer).
inline constexpr double kMaxRepetitionSpread = 1.5;
bool spreads_widely(const ResultRow& row);

// A camera "sees little" of its scene when fewer than this fraction of its
// primary rays hit, as the reference backend (Embree) traces them: the
// primary ray set then measures mostly empty space.
inline constexpr double kMinCameraCoverage = 0.25;

// What a scene's camera saw: the fraction of its primary rays that hit.
struct CameraCoverage {
  std::string scene;
  double hit_fraction = 0.0;
  std::string preview;  // the command that shows the camera's view: scripts/preview_camera ...
};
bool sees_little(const CameraCoverage& c);
// "camera sees little of the scene: 8.7 % of primary rays hit; check it with scripts/preview_camera ..."
std::string camera_warning(const CameraCoverage& c);

// How a table names a row's backend: its name, or for a plugin the name the
// plugin reports and the backend as given: "my_bvh (plugin:build/libmy.so)".
std::string backend_label(const ResultRow& row);

// The aligned per-scene table of speed and agreement, with each row's speed
// relative to the run's timing reference ("x NAME", ratio_to_reference;
// "x ref" and "-" in a run without one). A row whose
// repetitions spread widely carries '!' after its [min - max], explained
// under the table; a scene in `cameras` that sees little gets a warning line.
std::string format_results_table(const std::vector<ResultRow>& rows, const std::vector<CameraCoverage>& cameras = {});

// Per scene, the referee's verdicts per ray set and backend, as ray counts:
// false misses, false hits, wrong triangles, self-hits (secondary rays), and
// the t error in ulps (median and maximum over rays both hit).
std::string format_accuracy_table(const std::vector<AccuracyRow>& rows);

}  // namespace raybench
