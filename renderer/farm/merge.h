// Merging the parts of a split render (`pt merge`, renderer/farm/part.h): the parts' films are added in
// part order into the frame's film, whose image is then written like a one-machine render's.
//
// What the merge guarantees against the one-machine render of the same settings:
//   regions  bit-identical. Each pixel's sums come from exactly one part (the others add +0.0,
//            which changes no double), and a part's sums are the one-machine sums: the same
//            samples added in the same order.
//   samples  R, G, B within one float ulp, variance within the bound below. Both renders add the
//            same n samples (radiance is never negative) in double, in a different order: the
//            one-machine film one by one, the merge as part sums added together. Any order of n-1
//            additions is within gamma = (n-1) 2^-53 / (1 - (n-1) 2^-53) of the exact sum
//            (Higham, "Accuracy and Stability of Numerical Algorithms", 2002, sec. 4.2), so the two
//            sums differ by at most 2 gamma S, the double means by 2 gamma + 2^-52 relative: for
//            n <= 2^24 below 2^-28, far under a float's spacing (2^-24 relative), so the rounded
//            floats are equal or neighbours. The variance of the mean v = (Q - S^2/n) / (n (n-1))
//            suffers the cancellation in Q - S^2/n: with S^2/n <= Q, its error is at most
//            (6 gamma + 4 2^-53) Q / (n (n-1)) = (6 gamma + 4 2^-53) (v + m^2/(n-1)), plus one
//            float ulp of v for the two roundings to float; kVarianceBound below is that bound.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "renderer/render/film.h"
#include "renderer/farm/part.h"

namespace pt {

// |merged - single| allowed for a variance-of-mean value v with mean m over n samples: the
// bound above, without the float ulp (which the caller adds for its float).
inline double variance_merge_bound(double v, double m, double n) {
  if (n < 2) return 0;
  double u = 0x1p-53, gamma = (n - 1) * u / (1 - (n - 1) * u);
  return (6 * gamma + 4 * u) * (v + m * m / (n - 1));
}

struct MergedParts {
  Film film;
  std::map<std::string, std::string> metadata;  // the render's pt:* keys, part keys removed
  SplitKind split = SplitKind::kRegions;
  int parts = 0;
  int frame_spp = 0;
  // One line per part that holds fewer samples than its range (interrupted or time-limited):
  // "a.exr: part 1/4 holds 10 to 12 of its 16 samples".
  std::vector<std::string> short_parts;
};

// Reads, checks and adds the parts. Throws pt::Error naming the offending file when parts come from
// different scenes, settings, seeds or splits, when a part is duplicated or missing, or when a file
// is not a pt part; nothing is written here.
MergedParts merge_parts(const std::vector<std::string>& paths);

}  // namespace pt
