// What the pipeline promises of its output, checked on the output's quality report.
//
// Every stage refuses edits that would create a self-intersection, a non-manifold element or a
// degenerate face, but it cannot remove what it was given: a tangle of the input that the cleaning
// could not repair (two interpenetrating closed sheets, say) stays in the output, and a hole longer
// than the cleaning's limit stays open. A remesher that then reports success in silence hands an
// invalid mesh to TetGen or a BEM solver. OutputVerdict::Of compares the final report with the
// promises that hold for the stages that ran and says, in words, what is missed and why:
//  - validity (always): no self-intersecting pair, 2-manifold, no degenerate face;
//  - closed: no boundary edge (TetGen needs a closed surface);
//  - the angle bounds, when small-angle elimination ran (its promise: no angle below the min
//    angle, none above the max angle);
//  - V567, when valence optimization ran (Khan et al.'s 99.8 %).
// The callers (CLI, plugin) print the verdict; the CLI also turns an invalid output into a
// distinct exit status.
#pragma once

#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/quality_report_format.h>

namespace molremesh {

/// The promises to check, and what earlier stages reported that explains a miss.
struct OutputTargets {
  bool checkAngles = false;   ///< the angle bounds below are promised (small-angle elimination ran)
  double minAngleDeg = 30.0;  ///< no angle below it
  double maxAngleDeg = 120.0; ///< no angle above it
  bool checkValence = false;  ///< the V567 share below is promised (valence optimization ran)
  double minV567Percent = 99.8;
  // Causes, from the cleaning stage (0 when it did not run or found none).
  std::size_t unrepairedTangles = 0; ///< intersecting regions of the input left as they were
  std::size_t unfilledHoles = 0;     ///< holes of the input left open
  std::size_t largestUnfilledHoleEdges = 0;
  int maxHoleEdges = 0;               ///< the cleaning's hole size limit (for the advice)
  bool rebuiltVolumetrically = false; ///< the cleaning rebuilt the surface (so thin parts are gone)
  bool rebuildTried = false;          ///< a run on the rebuilt surface was made and not kept
};

struct OutputVerdict {
  std::vector<std::string> invalid; ///< validity broken: the output is not a valid surface mesh
  std::vector<std::string> shortOf; ///< targets missed by a valid output

  bool Valid() const { return invalid.empty(); }
  bool AllMet() const { return invalid.empty() && shortOf.empty(); }

  /// Compares `out` (with self-intersections counted) with the targets.
  static OutputVerdict Of(const QualityReport& out, const OutputTargets& targets) {
    OutputVerdict v;
    auto text = [](auto... parts) {
      std::ostringstream s;
      (s << ... << parts);
      return s.str();
    };
    if (out.selfIntersectionsComputed) {
      const std::size_t pairs = out.selfIntersectingPairs, overlaps = out.adjacentOverlapPairs;
      if (pairs + overlaps > 0) {
        std::string why = targets.unrepairedTangles > 0
                              ? text(" (left from the input: ", targets.unrepairedTangles,
                                     targets.unrepairedTangles == 1 ? " tangle" : " tangles",
                                     " of intersecting faces the clean stage could not repair, such as two "
                                     "interpenetrating closed sheets)")
                              : std::string();
        v.invalid.push_back(text(pairs, " self-intersecting face pair", pairs == 1 ? "" : "s",
                                 overlaps > 0 ? text(" and ", overlaps,
                                                     " pairs of faces sharing a vertex that also meet "
                                                     "elsewhere")
                                              : std::string(),
                                 why));
      }
    }
    if (out.nonManifoldEdges > 0 || out.nonManifoldVertices > 0)
      v.invalid.push_back(text(out.nonManifoldEdges, " non-manifold edges and ", out.nonManifoldVertices,
                               " non-manifold vertices"));
    if (out.degenerateFaces > 0) v.invalid.push_back(text(out.degenerateFaces, " degenerate faces"));

    if (out.boundaryEdges > 0) {
      std::string why;
      if (targets.unfilledHoles > 0)
        why = text(
            " (the clean stage left ", targets.unfilledHoles, targets.unfilledHoles == 1 ? " hole" : " holes",
            " of the input open, the longest with ", targets.largestUnfilledHoleEdges, " edges",
            targets.maxHoleEdges > 0 && targets.largestUnfilledHoleEdges > std::size_t(targets.maxHoleEdges)
                ? text(": above the clean stage's hole size limit of ", targets.maxHoleEdges, " edges")
                : std::string(": no valid fill was found"),
            ")");
      v.shortOf.push_back(text("not closed: ", out.boundaryEdges, " boundary edges in ", out.boundaryLoops,
                               out.boundaryLoops == 1 ? " loop" : " loops", why,
                               "; boundary vertices are kept, so the angles there may stay out of bounds, "
                               "and TetGen needs a closed surface"));
    }
    if (targets.checkAngles && out.faces > 0) {
      // The usual cause: parts of the input thinner than L, which only a rebuild removes.
      const std::string advice = targets.rebuiltVolumetrically || targets.rebuildTried
                                     ? std::string()
                                     : " (parts of the input thinner than the edge length, such as fins, "
                                       "tubes and pinched voids, keep such angles; the clean stage's "
                                       "volumetric rebuild removes them)";
      const bool maxMissed = out.angleMax > targets.maxAngleDeg; // the advice goes on the last line
      if (out.angleMin < targets.minAngleDeg)
        v.shortOf.push_back(text("smallest angle ", detail::FormatNumber(out.angleMin, 2),
                                 " deg, below the min angle ", targets.minAngleDeg, " deg",
                                 maxMissed ? std::string() : advice));
      if (maxMissed)
        v.shortOf.push_back(text("largest angle ", detail::FormatNumber(out.angleMax, 2),
                                 " deg, above the max angle ", targets.maxAngleDeg, " deg", advice));
    }
    if (targets.checkValence && out.interiorVertices > 0 && out.v567Percent < targets.minV567Percent)
      v.shortOf.push_back(text("V567 ", detail::FormatNumber(out.v567Percent, 2), " %, below ",
                               targets.minV567Percent, " %"));
    return v;
  }

  /// One line per miss, invalid ones first, each prefixed by `prefix`.
  std::string Lines(const std::string& prefix) const {
    std::string s;
    for (const auto& line : invalid) s += prefix + "not valid: " + line + "\n";
    for (const auto& line : shortOf) s += prefix + "short of a target: " + line + "\n";
    return s;
  }
};

} // namespace molremesh
