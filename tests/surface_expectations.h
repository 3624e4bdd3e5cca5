// Expectations on a remeshed or generated surface, shared by the test programs.
#pragma once

#include <gtest/gtest.h>

#include <vcg_ext/quality/mesh_quality.h>

namespace molremesh::test {

/// A closed, 2-manifold, outward surface without degenerate faces, crossing or overlapping faces.
inline void ExpectValidClosedSurface(const QualityReport& q) {
  EXPECT_GT(q.faces, 0u);
  EXPECT_EQ(q.boundaryEdges, 0u);
  EXPECT_EQ(q.nonManifoldEdges, 0u);
  EXPECT_EQ(q.nonManifoldVertices, 0u);
  EXPECT_EQ(q.degenerateFaces, 0u);
  EXPECT_EQ(q.selfIntersectingPairs, 0u);
  EXPECT_EQ(q.adjacentOverlapPairs, 0u);
  EXPECT_GT(q.volume, 0.0); // outward
}

template <class MeshType>
void ExpectValidClosedSurface(const MeshType& m) {
  ExpectValidClosedSurface(MeshQuality<MeshType>::Compute(m));
}

} // namespace molremesh::test
