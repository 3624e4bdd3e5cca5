// LocalRemeshingOps: topology preparation and checks (PrepareTopology, AdjacencyProblem), Init
// (footpoints, free lists, intersection grid) and Finish (compaction, normals).
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
void LocalRemeshingOps<MeshType>::UpdateGuardCosines() {
  const double toRad = kPi / 180.0;
  cosMinAngleGuard_ = std::cos(guards_.minAngleDeg * toRad);
  cosMaxAngleGuard_ = std::cos(guards_.maxAngleDeg * toRad);
  cosNormalGuard_ = std::cos(guards_.maxNormalDeviationDeg * toRad);
  cosFoldGuard_ = std::cos(guards_.maxFoldAngleDeg * toRad);
  const double minArea2 = 2.0 * guards_.minAreaFactor * L_ * L_;
  minArea2_ = minArea2 * minArea2;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::NewStamp() {
  if (++stamp_ == 0) {
    std::fill(vertStamp_.begin(), vertStamp_.end(), 0);
    std::fill(faceStamp_.begin(), faceStamp_.end(), 0);
    stamp_ = 1;
  }
}

template <class MeshType>
std::string LocalRemeshingOps<MeshType>::AdjacencyProblem(const MeshType& m) {
  std::vector<std::size_t> uses(m.vert.size(), 0);
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const FaceType& f = m.face[fi];
    if (f.IsD()) continue;
    const std::string where = "face " + std::to_string(fi) + ": ";
    for (int e = 0; e < 3; ++e) {
      if (f.cV(e) == nullptr || f.cV(e)->IsD()) return where + "missing or deleted vertex";
      ++uses[vcg::tri::Index(m, f.cV(e))];
      const FaceType* g = f.cFFp(e);
      const int w = f.cFFi(e);
      if (g == nullptr || g->IsD()) return where + "FF link to a missing or deleted face";
      if (g == &f) {
        if (w != e) return where + "border edge with a wrong FF index";
        continue;
      }
      if (w < 0 || w > 2 || g->cFFp(w) != &f || g->cFFi(w) != e) return where + "FF link not mutual";
      if (g->cV(w) != f.cV((e + 1) % 3) || g->cV((w + 1) % 3) != f.cV(e))
        return where + "FF link across another edge";
    }
  }
  for (std::size_t vi = 0; vi < m.vert.size(); ++vi) {
    const VertexType& v = m.vert[vi];
    if (v.IsD()) continue;
    std::size_t listed = 0;
    if (v.cVFp() != nullptr) {
      for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
        if (++listed > uses[vi]) return "vertex " + std::to_string(vi) + ": VF list too long (or cyclic)";
        if (it.F()->IsD()) return "vertex " + std::to_string(vi) + ": VF list holds a deleted face";
        if (it.I() < 0 || it.I() > 2 || it.F()->cV(it.I()) != &v)
          return "vertex " + std::to_string(vi) + ": VF entry does not point back";
      }
    }
    if (listed != uses[vi]) return "vertex " + std::to_string(vi) + ": VF list misses faces";
  }
  return std::string();
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::PrepareTopology(MeshType& m, std::string* error, int threads) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
    return fail("face-face and vertex-face adjacency must be enabled on the mesh");
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    if (f.cV(0) == nullptr || f.cV(1) == nullptr || f.cV(2) == nullptr || f.cV(0) == f.cV(1) ||
        f.cV(1) == f.cV(2) || f.cV(2) == f.cV(0))
      return fail("the mesh has faces with a repeated or missing vertex; clean it first");
  }
  UpdateAdjacency(m, threads);

  // 2-manifold and consistently oriented: every edge has one or two faces, two faces traverse
  // it in opposite directions, and the faces at each vertex form a single fan. Read-only, so
  // the checks run on `threads` cores (0 = all; each thread counts into its own slot).
  threads = ResolveThreadCount(threads);
  std::vector<std::array<std::size_t, 3>> counts(std::size_t(threads), {0, 0, 0});
  ParallelFor(m.face.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    std::array<std::size_t, 3>& c = counts[std::size_t(t)];
    for (std::size_t fi = begin; fi < end; ++fi) {
      const FaceType& f = m.face[fi];
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        if (IsBorder(f, e)) continue;
        const FaceType* g = f.cFFp(e);
        const int w = f.cFFi(e);
        if (g->cFFp(w) != &f)
          ++c[0];
        else if (g->cV(w) != f.cV((e + 1) % 3) || g->cV((w + 1) % 3) != f.cV(e))
          ++c[1];
      }
    }
  });
  std::size_t nonManifoldEdges = 0, misoriented = 0, nonManifoldVertices = 0;
  for (const auto& c : counts) {
    nonManifoldEdges += c[0];
    misoriented += c[1];
  }
  if (nonManifoldEdges > 0) return fail("the mesh has non-manifold edges; run the cleaning stage first");
  if (misoriented > 0) return fail("the mesh is not consistently oriented; run the cleaning stage first");
  ParallelFor(m.vert.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    for (std::size_t vi = begin; vi < end; ++vi) {
      VertexType& v = m.vert[vi];
      if (v.IsD() || v.VFp() == nullptr) continue;
      std::size_t inList = 0;
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) ++inList;
      // Walk the fan through FF in both directions from the first face.
      std::size_t inFan = 0;
      FacePointer f0 = v.VFp();
      FacePointer f = f0;
      int k = v.VFi();
      bool border = false;
      do {
        ++inFan;
        FacePointer g = f->FFp(k); // across edge (v, next)
        if (g == f) {
          border = true;
          break;
        }
        k = IndexIn(*g, &v);
        f = g;
      } while (f != f0 && inFan <= inList);
      if (border) {
        f = f0;
        k = v.VFi();
        for (;;) {
          FacePointer g = f->FFp((k + 2) % 3); // across edge (prev, v)
          if (g == f || inFan > inList) break;
          ++inFan;
          k = IndexIn(*g, &v);
          f = g;
        }
      }
      if (inFan != inList) ++counts[std::size_t(t)][2];
    }
  });
  for (const auto& c : counts) nonManifoldVertices += c[2];
  if (nonManifoldVertices > 0)
    return fail("the mesh has non-manifold vertices; run the cleaning stage first");

  return true;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::Init(std::string* error, bool meshIsReference, bool topologyReady,
                                       bool lazyFootpoints, const std::vector<int>* globalFeet) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!vcg::tri::HasFFAdjacency(m_) || !vcg::tri::HasVFAdjacency(m_))
    return fail("face-face and vertex-face adjacency must be enabled on the mesh");
  if (ref_.Empty()) return fail("the reference surface is empty");
  if (!(L_ > 0) || !std::isfinite(L_)) return fail("the target edge length must be positive");
  if (!topologyReady && !PrepareTopology(m_, error, threads_)) return false;
  hasBorder_ = false;
  for (const auto& f : m_.face)
    if (!f.IsD() && (IsBorder(f, 0) || IsBorder(f, 1) || IsBorder(f, 2))) hasBorder_ = true;
  UpdateGuardCosines();
  const vcg::Box3d& rb = ref_.BoundingBox();
  const double maxAbs = std::max({std::fabs(rb.min[0]), std::fabs(rb.min[1]), std::fabs(rb.min[2]),
                                  std::fabs(rb.max[0]), std::fabs(rb.max[1]), std::fabs(rb.max[2])});
  tol_ = 1e-12 * (maxAbs + L_);
  margin_ = 1e-9 * (maxAbs + L_);

  foot_.assign(m_.vert.size(), -1);
  batchIndex_.assign(m_.vert.size(), -1);
  locked_.assign(m_.vert.size(), 0);
  vertStamp_.assign(m_.vert.size(), 0);
  faceStamp_.assign(m_.face.size(), 0);
  stamp_ = 0;
  freeVerts_.clear();
  freeFaces_.clear();
  // Recycle elements deleted before (in reverse so the lowest index is taken first).
  for (std::size_t i = m_.vert.size(); i-- > 0;)
    if (m_.vert[i].IsD()) freeVerts_.push_back(i);
  for (std::size_t i = m_.face.size(); i-- > 0;)
    if (m_.face[i].IsD()) freeFaces_.push_back(i);

  // Footpoints.
  std::vector<std::uint8_t> needsSearch(m_.vert.size(), 0);
  for (std::size_t i = 0; i < m_.vert.size(); ++i) {
    const VertexType& v = m_.vert[i];
    if (v.IsD() || v.cVFp() == nullptr) continue;
    needsSearch[i] = 1;
    if (globalFeet != nullptr && i < globalFeet->size() && (*globalFeet)[i] >= 0) {
      foot_[i] = (*globalFeet)[i];
      needsSearch[i] = 0;
      continue;
    }
    if (!meshIsReference) continue;
    const int rf = ref_.ReferenceFaceOf(FIndex(*v.cVFp()));
    if (rf < 0) continue;
    const int k = v.cVFi();
    if (ref_.Corner(rf, k) == Pos(&v)) {
      foot_[i] = rf;
      needsSearch[i] = 0;
    }
  }
  if (lazyFootpoints) {
    for (std::size_t i = 0; i < m_.vert.size(); ++i)
      if (needsSearch[i]) foot_[i] = kUnknownFoot;
  } else {
    ParallelFor(m_.vert.size(), threads_, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t i = begin; i < end; ++i)
        if (needsSearch[i]) foot_[i] = ref_.ProjectGlobal(Pos(&m_.vert[i])).face;
    });
  }

  grid_.Reset(guards_.gridCellFactor * L_, rb.min);
  grid_.InsertAll(
      m_.face.size(),
      [&](std::size_t i, vcg::Box3d& box) {
        if (m_.face[i].IsD()) return false;
        box = FaceBox(m_.face[i]);
        return true;
      },
      threads_);
  lastRefusal_ = OpRefusal::None;
  return true;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Finish() {
  if (HasPendingMoves()) VerifyPendingMoves();
  vcg::tri::Allocator<MeshType>::CompactEveryVector(m_);
  if (vcg::tri::HasPerFaceNormal(m_)) vcg::tri::UpdateNormal<MeshType>::PerFaceNormalized(m_);
  if (vcg::tri::HasPerVertexNormal(m_)) vcg::tri::UpdateNormal<MeshType>::PerVertexNormalized(m_);
  foot_.clear();
  batchIndex_.clear();
  locked_.clear();
  vertStamp_.clear();
  faceStamp_.clear();
  freeVerts_.clear();
  freeFaces_.clear();
  grid_.Reset(1.0, Point(0, 0, 0));
}

} // namespace molremesh
