// LocalRemeshingOps: batch (Jacobi) vertex moves and their verification: all moves applied, every
// changed face verified in parallel, the vertices of failing faces put back until nothing fails.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
typename LocalRemeshingOps<MeshType>::FaceVerdict
LocalRemeshingOps<MeshType>::VerifyBatchFace(std::size_t fi, FaceHashGrid::QueryMarks& marks,
                                             bool intersections, const TrianglePairScan* scan) const {
  using local_ops_detail::UnitNormal;
  FaceVerdict verdict;
  const FaceType& f = m_.face[fi];
  std::array<Point, 3> p, o;
  std::array<VertexPointer, 3> v{};
  std::array<int, 3> feet{}, oldFeet{};
  for (int k = 0; k < 3; ++k) {
    v[k] = const_cast<VertexPointer>(f.cV(k));
    p[k] = Pos(v[k]);
    o[k] = ToPoint(OldCoord(v[k]));
    feet[k] = foot_[VIndex(*v[k])];
    oldFeet[k] = OldFoot(v[k]);
  }
  const bool moved = scan ? scan->Input(fi).moved : MovedInBatch(f);
  const Point n = scan ? scan->Normal(fi) : UnitNormal(p);
  auto fail = [&](int partner) {
    verdict.fail = true;
    verdict.partner = partner;
    return verdict;
  };
  if (moved) {
    const Point cross = (p[1] - p[0]) ^ (p[2] - p[0]);
    if (!(cross.SquaredNorm() > minArea2_)) return fail(-1);
    double cmin, cmax, ocmin, ocmax;
    AngleCosines(p[0], p[1], p[2], cmin, cmax);
    if (cmin > cosMinAngleGuard_ || cmax < cosMaxAngleGuard_) {
      AngleCosines(o[0], o[1], o[2], ocmin, ocmax);
      if (cmin > cosMinAngleGuard_ && cmin > ocmin) return fail(-1);
      if (cmax < cosMaxAngleGuard_ && cmax < ocmax) return fail(-1);
    }
    auto deviation = [&](const Point& normal, const std::array<int, 3>& corners) {
      const Point s = RefNormalSum(corners);
      const double len = s.Norm();
      return len > 1e-12 ? (normal * s) / len : -1.0;
    };
    const double dev = deviation(n, feet);
    if (dev < cosNormalGuard_ && dev < deviation(UnitNormal(o), oldFeet)) return fail(-1);
  }
  // Folds across the edges (each edge once when both faces are being verified).
  for (int e = 0; e < 3; ++e) {
    const FaceType* g = f.cFFp(e);
    if (g == &f) continue;
    const std::size_t gi = FIndex(*g);
    if (faceStamp_[gi] == stamp_ && gi < fi) continue;
    if (!moved && !(scan ? scan->Input(gi).moved : MovedInBatch(*g))) continue;
    Point ng;
    if (scan) {
      ng = scan->Normal(gi);
    } else {
      std::array<Point, 3> q;
      for (int k = 0; k < 3; ++k) q[k] = Pos(g->cV(k));
      ng = UnitNormal(q);
    }
    const double c = n * ng;
    if (c >= cosFoldGuard_) continue;
    std::array<Point, 3> qo;
    for (int k = 0; k < 3; ++k) qo[k] = ToPoint(OldCoord(g->cV(k)));
    if (c < UnitNormal(o) * UnitNormal(qo)) return fail(int(gi));
  }
  if (!guards_.checkIntersections || !intersections) return verdict;
  // New intersecting pairs: against every face whose (stored, outward rounded) box touches
  // this one's (the grid is up to date for the faces being verified).
  int partner = -1;
  grid_.QueryFace(fi, marks, [&](std::size_t gi) {
    if (partner >= 0) return;
    if (faceStamp_[gi] == stamp_ && gi < fi) return; // verified from the other side
    const FaceType& g = m_.face[gi];
    if (!moved && !MovedInBatch(g)) return; // two untouched faces: not new
    std::array<Point, 3> q;
    std::array<VertexPointer, 3> gv{};
    for (int k = 0; k < 3; ++k) {
      gv[k] = const_cast<VertexPointer>(g.cV(k));
      q[k] = Pos(gv[k]);
    }
    if (local_ops_detail::FacesIntersect(p, n, v, q, UnitNormal(q), gv, margin_)) partner = int(gi);
  });
  if (partner >= 0) return fail(partner);
  return verdict;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::MoveVertexUnchecked(VertexPointer v, const Point& onSurface, int footFace) {
  const std::size_t vi = VIndex(*v);
  if (v->IsD() || v->VFp() == nullptr || locked_[vi] || footFace < 0 || IsBoundaryVertex(*v)) return false;
  const CoordType stored = ToCoord(onSurface);
  if (batchIndex_[vi] < 0) {
    if (stored == v->cP()) return true;
    batchIndex_[vi] = int(batch_.size());
    batch_.push_back({std::uint32_t(vi), stored, v->cP(), footFace, foot_[vi], true});
  } else {
    batch_[batchIndex_[vi]].target = stored;
    batch_[batchIndex_[vi]].targetFoot = footFace;
  }
  v->P() = stored;
  foot_[vi] = footFace;
  return true;
}

template <class MeshType>
BatchMoveResult LocalRemeshingOps<MeshType>::MoveVerticesJacobi(const std::vector<std::uint32_t>& vertices,
                                                                const std::vector<Point>& targets,
                                                                const std::vector<int>& feet, int threads) {
  std::size_t refused = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!MoveVertexUnchecked(&m_.vert[vertices[i]], targets[i], feet[i])) ++refused;
  BatchMoveResult result = VerifyPendingMoves(threads);
  result.rejected += refused;
  return result;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::CollectStarFaces(const std::vector<std::uint32_t>& vertices) {
  NewStamp();
  dirty_.clear();
  for (const std::uint32_t vi : vertices)
    for (vcg::face::VFIterator<FaceType> it(&m_.vert[vi]); !it.End(); ++it) {
      const std::size_t fi = FIndex(*it.F());
      if (faceStamp_[fi] != stamp_) {
        faceStamp_[fi] = stamp_;
        dirty_.push_back(fi);
      }
    }
  std::sort(dirty_.begin(), dirty_.end());
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::CollectBatchFaces(int threads) {
  if (4 * batch_.size() > std::size_t(m_.vn)) {
    // Most vertices moved: one parallel pass over the faces finds the changed ones.
    NewStamp();
    ParallelFor(m_.face.size(), threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t fi = begin; fi < end; ++fi)
        if (!m_.face[fi].IsD() && MovedInBatch(m_.face[fi])) faceStamp_[fi] = stamp_;
    });
    dirty_.clear();
    for (std::size_t fi = 0; fi < m_.face.size(); ++fi)
      if (faceStamp_[fi] == stamp_) dirty_.push_back(fi);
  } else {
    std::vector<std::uint32_t> moved;
    moved.reserve(batch_.size());
    for (const BatchEntry& b : batch_) moved.push_back(b.vertex);
    CollectStarFaces(moved);
  }
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::UpdateDirtyBoxes(int threads) {
  updateInPlace_.assign(dirty_.size(), 0);
  ParallelFor(dirty_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
      updateInPlace_[i] = grid_.UpdateInPlace(dirty_[i], FaceBox(m_.face[dirty_[i]])) ? 1 : 0;
  });
  for (std::size_t i = 0; i < dirty_.size(); ++i)
    if (!updateInPlace_[i]) grid_.Update(dirty_[i], FaceBox(m_.face[dirty_[i]]));
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::BuildBatchScan(int threads) {
  scanPositions_.resize(m_.vert.size());
  ParallelFor(m_.vert.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t vi = begin; vi < end; ++vi) scanPositions_[vi] = Pos(&m_.vert[vi]);
  });
  scan_.Build(
      m_.face.size(), scanPositions_.data(),
      [&](std::size_t fi, TrianglePairScan::Triangle& t) {
        const FaceType& f = m_.face[fi];
        if (f.IsD()) return;
        t.live = true;
        t.moved = MovedInBatch(f);
        for (int k = 0; k < 3; ++k) t.v[k] = std::uint32_t(VIndex(*f.cV(k)));
      },
      threads);
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::FindBatchScanPairs(int threads) {
  // Pairs sharing an edge are never reported, and pairs sharing one vertex are settled star by
  // star: none of them can meet when the star is a simple fan, which nearly every star is.
  scan_.FindPairs(
      threads,
      [&](std::uint32_t a, std::uint32_t b) {
        return local_ops_detail::FacesIntersect(scan_.Corners(a), scan_.Normal(a), scan_.Input(a).v,
                                                scan_.Corners(b), scan_.Normal(b), scan_.Input(b).v, margin_);
      },
      scanPairs_, /*skipSharedVertex=*/true);
  StarPairs(scan_, threads, scanPairs_);
  std::sort(scanPairs_.begin(), scanPairs_.end());
  scanPairs_.erase(std::unique(scanPairs_.begin(), scanPairs_.end()), scanPairs_.end());
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::RevertFailingFaces(std::vector<std::uint32_t>& reverted) {
  reverted.clear();
  auto revertFace = [&](const FaceType& f) {
    for (int k = 0; k < 3; ++k) {
      const int b = batchIndex_[VIndex(*f.cV(k))];
      if (b < 0 || !batch_[b].atTarget) continue;
      BatchEntry& e = batch_[b];
      e.atTarget = false;
      m_.vert[e.vertex].P() = e.old;
      foot_[e.vertex] = e.oldFoot;
      reverted.push_back(e.vertex);
    }
  };
  for (std::size_t i = 0; i < dirty_.size(); ++i) {
    if (!verdicts_[i].fail) continue;
    revertFace(m_.face[dirty_[i]]);
    if (verdicts_[i].partner >= 0) revertFace(m_.face[verdicts_[i].partner]);
  }
  for (const auto& [a, b] : scanPairs_) {
    revertFace(m_.face[a]);
    revertFace(m_.face[b]);
  }
}

template <class MeshType>
BatchMoveResult LocalRemeshingOps<MeshType>::VerifyPendingMoves(int threads) {
  BatchMoveResult result;
  if (batch_.empty()) return result;
  if (threads <= 0) threads = threads_;
  const int nThreads = ResolveThreadCount(threads);
  CollectBatchFaces(nThreads);
  if (int(marks_.size()) < nThreads) marks_.resize(nThreads);
  std::vector<std::uint32_t> reverted;
  while (!dirty_.empty()) {
    ++result.rounds;
    UpdateDirtyBoxes(nThreads);
    // When most faces changed, one sweep over all of them finds the intersecting pairs faster
    // than a grid query per face.
    const bool sweep = guards_.checkIntersections && 4 * dirty_.size() > std::size_t(m_.fn);
    scanPairs_.clear();
    // The sweep's scan is built first: the per-face guards read its normals and moved flags.
    if (sweep) BuildBatchScan(nThreads);
    verdicts_.assign(dirty_.size(), FaceVerdict());
    ParallelFor(
        dirty_.size(), nThreads,
        [&](std::size_t begin, std::size_t end, int t) {
          for (std::size_t i = begin; i < end; ++i)
            verdicts_[i] = VerifyBatchFace(dirty_[i], marks_[t], !sweep, sweep ? &scan_ : nullptr);
        },
        256);
    if (sweep) FindBatchScanPairs(nThreads);
    RevertFailingFaces(reverted);
    if (reverted.empty()) break;
    CollectStarFaces(reverted);
  }
  for (const BatchEntry& b : batch_) {
    batchIndex_[b.vertex] = -1;
    if (b.atTarget)
      ++result.applied;
    else
      ++result.rejected;
  }
  stats_.moves += result.applied;
  batch_.clear();
  return result;
}

} // namespace molremesh
