// LocalRemeshingOps: the boundary loop of a disk of faces and its guarded replacement by new faces.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
bool LocalRemeshingOps<MeshType>::DiskBoundary(const std::vector<FacePointer>& region,
                                               std::vector<VertexPointer>& loop,
                                               std::vector<VertexPointer>& interior) {
  loop.clear();
  interior.clear();
  if (region.empty()) return Refuse(OpRefusal::Topology), false;
  NewStamp();
  for (const FacePointer f : region) {
    if (f->IsD() || faceStamp_[FIndex(*f)] == stamp_) return Refuse(OpRefusal::Topology), false;
    faceStamp_[FIndex(*f)] = stamp_;
  }
  // Boundary edges: region edges whose other side is outside the region. vertStamp_ marks the
  // start vertex of a boundary edge; next_ holds its end (one outgoing edge per vertex allowed).
  std::vector<std::pair<VertexPointer, VertexPointer>>& edges = loopEdges_;
  edges.clear();
  for (const FacePointer f : region)
    for (int e = 0; e < 3; ++e) {
      if (IsBorder(*f, e)) return Refuse(OpRefusal::Boundary), false;
      if (faceStamp_[FIndex(*f->FFp(e))] != stamp_) edges.emplace_back(f->V(e), f->V((e + 1) % 3));
    }
  if (edges.size() < 3) return Refuse(OpRefusal::Topology), false;
  for (const auto& [a, b] : edges) {
    if (vertStamp_[VIndex(*a)] == stamp_) return Refuse(OpRefusal::Topology), false; // pinched loop
    vertStamp_[VIndex(*a)] = stamp_;
  }
  // Walk the loop (edges are few: a linear search per step is cheapest).
  loop.push_back(edges[0].first);
  VertexPointer cur = edges[0].second;
  while (cur != loop.front()) {
    if (loop.size() > edges.size()) return Refuse(OpRefusal::Topology), false;
    loop.push_back(cur);
    const auto it = std::find_if(edges.begin(), edges.end(), [&](const auto& ab) { return ab.first == cur; });
    if (it == edges.end()) return Refuse(OpRefusal::Topology), false;
    cur = it->second;
  }
  if (loop.size() != edges.size()) return Refuse(OpRefusal::Topology), false; // several loops
  // Interior vertices: on region faces, not on the loop; all their faces must be region faces.
  for (const FacePointer f : region)
    for (int k = 0; k < 3; ++k) {
      const VertexPointer u = f->V(k);
      if (vertStamp_[VIndex(*u)] == stamp_) continue;
      vertStamp_[VIndex(*u)] = stamp_;
      for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
        if (faceStamp_[FIndex(*it.F())] != stamp_) return Refuse(OpRefusal::Topology), false;
      interior.push_back(u);
    }
  // Euler characteristic of a disk: V - E + F = 1.
  const long V = long(loop.size() + interior.size()), F = long(region.size());
  const long E = (3 * F + long(loop.size())) / 2;
  if (V - E + F != 1) return Refuse(OpRefusal::Topology), false;
  return true;
}

template <class MeshType>
OpRefusal
LocalRemeshingOps<MeshType>::CheckDiskTriangulation(const std::vector<VertexPointer>& loop,
                                                    const std::vector<std::array<int, 3>>& triangles,
                                                    std::size_t total) const {
  const std::size_t n = loop.size(), k = total - n;
  // The triangulation must cover the disk once: loop edges once in loop direction, inner edges
  // once in each direction, no inner edge along the loop reversed, every index in range.
  std::vector<std::pair<int, int>> directed;
  for (const auto& t : triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      if (a < 0 || b < 0 || std::size_t(a) >= total || std::size_t(b) >= total || a == b)
        return OpRefusal::Topology;
      directed.emplace_back(a, b);
    }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return OpRefusal::Topology;
  auto hasDirected = [&](int a, int b) {
    return std::binary_search(directed.begin(), directed.end(), std::make_pair(a, b));
  };
  for (const auto& [a, b] : directed) {
    if (IsLoopEdge(a, b, n)) continue;
    if (IsLoopEdge(b, a, n) || !hasDirected(b, a)) return OpRefusal::Topology;
  }
  for (int i = 0; i < int(n); ++i)
    if (!hasDirected(i, (i + 1) % int(n))) return OpRefusal::Topology;
  for (std::size_t j = 0; j < k; ++j) // every new vertex is used
    if (std::none_of(directed.begin(), directed.end(),
                     [&](const auto& ab) { return ab.first == int(n + j); }))
      return OpRefusal::Topology;
  // New chords between loop vertices must not exist outside the region, nor join two locked ones.
  for (const auto& [a, b] : directed) {
    if (a >= int(n) || b >= int(n) || a > b || IsLoopEdge(a, b, n) || IsLoopEdge(b, a, n)) continue;
    if (locked_[VIndex(*loop[a])] && locked_[VIndex(*loop[b])]) return OpRefusal::Locked;
    for (vcg::face::VFIterator<FaceType> it(loop[a]); !it.End(); ++it) {
      if (faceStamp_[FIndex(*it.F())] == stamp_) continue;
      if (it.F()->V((it.I() + 1) % 3) == loop[b] || it.F()->V((it.I() + 2) % 3) == loop[b])
        return OpRefusal::Topology;
    }
  }
  return OpRefusal::None;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::PlaceDiskVertices(const std::vector<VertexPointer>& loop,
                                                    const std::vector<Point>& newPoints,
                                                    std::vector<Point>& pos, std::vector<int>& feet,
                                                    std::vector<CoordType>& stored) {
  const std::size_t n = loop.size(), k = newPoints.size();
  for (std::size_t i = 0; i < n; ++i) {
    pos[i] = Pos(loop[i]);
    feet[i] = foot_[VIndex(*loop[i])];
  }
  for (std::size_t j = 0; j < k; ++j) {
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < n; ++i)
      if ((pos[i] - newPoints[j]).SquaredNorm() < (pos[nearest] - newPoints[j]).SquaredNorm()) nearest = i;
    const SurfaceProjection proj = ref_.Project(newPoints[j], feet[nearest], scratch_);
    if (!proj.ok()) return false;
    stored[j] = ToCoord(proj.point);
    pos[n + j] = ToPoint(stored[j]);
    feet[n + j] = proj.face;
  }
  return true;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::ApplyDiskReplacement(
    const std::vector<FacePointer>& region, const std::vector<VertexPointer>& interior,
    const std::vector<VertexPointer>& loop, const std::vector<VertexPointer>& vid,
    const std::vector<CoordType>& stored, const std::vector<int>& feet,
    const std::vector<std::array<int, 3>>& triangles, const std::vector<FacePointer>& outFace,
    const std::vector<int>& outIndex, std::vector<VertexPointer>* created) {
  const std::size_t n = loop.size(), k = stored.size();
  // Apply: new vertices, new faces (their data from a region face), then drop the old ones.
  for (std::size_t j = 0; j < k; ++j) {
    const VertexPointer v = TakeFreeVertex();
    v->ImportData(*loop[0]);
    v->P() = stored[j];
    v->VFp() = nullptr;
    v->VFi() = -1;
    foot_[VIndex(*v)] = feet[n + j];
    locked_[VIndex(*v)] = 0;
    if (created) created->push_back(v);
  }
  std::vector<FacePointer> made;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const FacePointer f = TakeFreeFace();
    f->ImportData(*region[0]);
    f->ClearD();
    for (int c = 0; c < 3; ++c) f->V(c) = vid[triangles[t][c]];
    made.push_back(f);
  }
  for (const FacePointer f : region)
    for (int c = 0; c < 3; ++c) vcg::face::VFDetach(*f, c);
  for (const FacePointer f : region) Release(*f);
  for (const VertexPointer u : interior) Release(*u);
  for (std::size_t t = 0; t < made.size(); ++t) {
    const FacePointer f = made[t];
    for (int c = 0; c < 3; ++c) {
      const int a = triangles[t][c], b = triangles[t][(c + 1) % 3];
      if (IsLoopEdge(a, b, n)) {
        f->FFp(c) = outFace[a];
        f->FFi(c) = outIndex[a];
        outFace[a]->FFp(outIndex[a]) = f;
        outFace[a]->FFi(outIndex[a]) = c;
        continue;
      }
      const int s = newFaces_[t].internal[c];
      const FacePointer g = made[s];
      for (int d = 0; d < 3; ++d)
        if (triangles[s][d] == b && triangles[s][(d + 1) % 3] == a) {
          f->FFp(c) = g;
          f->FFi(c) = d;
        }
    }
  }
  for (const FacePointer f : made) {
    for (int c = 0; c < 3; ++c) VFAppend(f, c);
    grid_.Insert(FIndex(*f), FaceBox(*f));
  }
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::ReplaceDisk(const std::vector<FacePointer>& regionIn,
                                              const std::vector<VertexPointer>& loopIn,
                                              const std::vector<Point>& newPoints,
                                              const std::vector<std::array<int, 3>>& triangles,
                                              std::vector<VertexPointer>* created) {
  if (HasPendingMoves()) VerifyPendingMoves();
  if (created) created->clear();
  const std::size_t n = loopIn.size(), k = newPoints.size(), total = n + k;
  if (triangles.empty()) return Refuse(OpRefusal::Topology), false;
  // Element pointers may move when room is made: work on indices across EnsureFree.
  std::vector<std::size_t> regionIdx, loopIdx;
  for (const FacePointer f : regionIn) regionIdx.push_back(FIndex(*f));
  for (const VertexPointer v : loopIn) loopIdx.push_back(VIndex(*v));
  FacePointer any = regionIn.empty() ? nullptr : regionIn.front();
  if (any == nullptr) return Refuse(OpRefusal::Topology), false;
  EnsureFree(k, triangles.size(), any);
  std::vector<FacePointer> region;
  std::vector<VertexPointer> loop, interior;
  for (const std::size_t i : regionIdx) region.push_back(&m_.face[i]);
  for (const std::size_t i : loopIdx) loop.push_back(&m_.vert[i]);

  std::vector<VertexPointer> checkLoop;
  if (!DiskBoundary(region, checkLoop, interior)) return false;
  if (checkLoop.size() != n) return Refuse(OpRefusal::Topology), false;
  {
    const auto it = std::find(checkLoop.begin(), checkLoop.end(), loop[0]);
    if (it == checkLoop.end()) return Refuse(OpRefusal::Topology), false;
    std::rotate(checkLoop.begin(), it, checkLoop.end());
    if (checkLoop != loop) return Refuse(OpRefusal::Topology), false;
  }
  for (const VertexPointer u : interior)
    if (locked_[VIndex(*u)]) return Refuse(OpRefusal::Locked), false;
  // An inner edge of the disk (between two of its faces) disappears: like a split, collapse or
  // flip, the replacement never removes an edge between two locked vertices.
  for (const FacePointer f : region)
    for (int e = 0; e < 3; ++e)
      if (locked_[VIndex(*f->V(e))] && locked_[VIndex(*f->V((e + 1) % 3))] && f->FFp(e) != f &&
          faceStamp_[FIndex(*f->FFp(e))] == stamp_)
        return Refuse(OpRefusal::Locked), false;

  const OpRefusal cover = CheckDiskTriangulation(loop, triangles, total);
  if (cover != OpRefusal::None) return Refuse(cover), false;

  // New vertices on the reference, near the closest loop vertex.
  std::vector<Point> pos(total);
  std::vector<int> feet(total);
  std::vector<CoordType> stored(k);
  if (!PlaceDiskVertices(loop, newPoints, pos, feet, stored)) return Refuse(OpRefusal::Degenerate), false;
  // Identities for the new vertices until they exist: the free slots they will take.
  std::vector<VertexPointer> vid(total);
  for (std::size_t i = 0; i < n; ++i) vid[i] = loop[i];
  for (std::size_t j = 0; j < k; ++j) vid[n + j] = &m_.vert[freeVerts_[freeVerts_.size() - 1 - j]];

  // Outside neighbours of the loop edges.
  std::vector<FacePointer> outFace(n, nullptr);
  std::vector<int> outIndex(n, -1);
  for (const FacePointer f : region)
    for (int e = 0; e < 3; ++e) {
      const FacePointer o = f->FFp(e);
      if (faceStamp_[FIndex(*o)] == stamp_) continue;
      const std::size_t i = std::size_t(std::find(loop.begin(), loop.end(), f->V(e)) - loop.begin());
      outFace[i] = o;
      outIndex[i] = f->FFi(e);
    }
  oldFaces_ = region;
  newFaces_.clear();
  for (const auto& t : triangles) {
    NewFace nf;
    for (int c = 0; c < 3; ++c) {
      nf.v[c] = vid[t[c]];
      nf.p[c] = pos[t[c]];
      nf.foot[c] = feet[t[c]];
      nf.outside[c] = IsLoopEdge(t[c], t[(c + 1) % 3], n) ? outFace[t[c]] : nullptr;
    }
    newFaces_.push_back(nf);
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  ApplyDiskReplacement(region, interior, loop, vid, stored, feet, triangles, outFace, outIndex, created);
  ++stats_.replacements;
  lastRefusal_ = OpRefusal::None;
  return true;
}

} // namespace molremesh
