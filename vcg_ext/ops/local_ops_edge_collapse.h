// LocalRemeshingOps: guarded edge collapse (link condition, then the guards).
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
void LocalRemeshingOps<MeshType>::GlueAcross(FacePointer face, int e) {
  FacePointer a = face->FFp((e + 1) % 3);
  const int ia = face->FFi((e + 1) % 3);
  FacePointer b = face->FFp((e + 2) % 3);
  const int ib = face->FFi((e + 2) % 3);
  const bool aBorder = a == face, bBorder = b == face;
  if (!aBorder && !bBorder) {
    a->FFp(ia) = b;
    a->FFi(ia) = ib;
    b->FFp(ib) = a;
    b->FFi(ib) = ia;
  } else if (aBorder) {
    b->FFp(ib) = b;
    b->FFi(ib) = ib;
  } else {
    a->FFp(ia) = a;
    a->FFi(ia) = ia;
  }
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::ApplyCollapse(FacePointer f, int z, FacePointer g, int w, VertexPointer vr,
                                                VertexPointer vk, const CoordType& stored, int footK) {
  // Apply: glue the faces around f and g, then move vr's faces to vk.
  GlueAcross(f, z);
  if (g != nullptr) GlueAcross(g, w);
  vcg::face::VFDetach(*f);
  if (g != nullptr) vcg::face::VFDetach(*g);
  for (const auto& [face, k] : star0_) {
    if (face == f || face == g) continue;
    vcg::face::VFDetach(*face, k);
    face->V(k) = vk;
    VFAppend(face, k);
  }
  Release(*f);
  if (g != nullptr) Release(*g);
  Release(*vr);
  vk->P() = stored;
  foot_[VIndex(*vk)] = footK;
  for (const FacePointer face : oldFaces_)
    if (!face->IsD()) grid_.Update(FIndex(*face), FaceBox(*face));
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::CollapseEdge(FacePointer f, int z, double maxNewEdgeLength) {
  if (HasPendingMoves()) VerifyPendingMoves();
  const bool edgeBorder = IsBorder(*f, z);
  VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3);
  const bool l0 = locked_[VIndex(*v0)] != 0, l1 = locked_[VIndex(*v1)] != 0;
  if (l0 && l1) return Refuse(OpRefusal::Locked), false;
  const bool b0 = IsBoundaryVertex(*v0), b1 = IsBoundaryVertex(*v1);
  const bool canRemove0 = !l0 && (!b0 || edgeBorder);
  const bool canRemove1 = !l1 && (!b1 || edgeBorder);
  if (!canRemove0 && !canRemove1) return Refuse((l0 || l1) ? OpRefusal::Locked : OpRefusal::Boundary), false;
  // Remove v0 and keep v1 when possible; the survivor moves only if it could have been removed too.
  const bool removeV0 = canRemove0;
  const bool survivorMoves = canRemove0 && canRemove1;
  VertexPointer vr = removeV0 ? v0 : v1;
  VertexPointer vk = removeV0 ? v1 : v0;

  // Cheap pre-test of the edge lengths around the midpoint (the exact test follows at the
  // projected position): most refused collapses stop here, before any star is gathered.
  if (maxNewEdgeLength < std::numeric_limits<double>::infinity()) {
    const Point q = survivorMoves ? (Pos(v0) + Pos(v1)) * 0.5 : Pos(vk);
    const double max2 = maxNewEdgeLength * maxNewEdgeLength;
    for (const VertexPointer u : {v0, v1})
      for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
        for (const int j : {(it.I() + 1) % 3, (it.I() + 2) % 3})
          if ((Pos(it.F()->V(j)) - q).SquaredNorm() > max2) return Refuse(OpRefusal::EdgeLength), false;
  }
  GatherStar(vr, star0_); // star0_: star of the removed vertex
  GatherStar(vk, star1_);
  const auto& starR = star0_;
  const auto& starK = star1_;

  // Link condition.
  FacePointer g = edgeBorder ? nullptr : f->FFp(z);
  const int w = edgeBorder ? -1 : f->FFi(z);
  const VertexPointer vl = f->V((z + 2) % 3);
  const VertexPointer vrr = edgeBorder ? nullptr : g->V((w + 2) % 3);
  if (vl == vrr) return Refuse(OpRefusal::Topology), false;
  if (IsBorder(*f, (z + 1) % 3) && IsBorder(*f, (z + 2) % 3)) return Refuse(OpRefusal::Topology), false;
  if (!edgeBorder && IsBorder(*g, (w + 1) % 3) && IsBorder(*g, (w + 2) % 3))
    return Refuse(OpRefusal::Topology), false;
  for (const VertexPointer o : {vl, vrr})
    if (o != nullptr && !IsBoundaryVertex(*o) && Valence(*o) <= 3) return Refuse(OpRefusal::Topology), false;
  NewStamp();
  for (const auto& [face, k] : starR) {
    vertStamp_[VIndex(*face->V((k + 1) % 3))] = stamp_;
    vertStamp_[VIndex(*face->V((k + 2) % 3))] = stamp_;
  }
  for (const auto& [face, k] : starK)
    for (const int j : {(k + 1) % 3, (k + 2) % 3}) {
      const VertexPointer u = face->V(j);
      if (u != vl && u != vrr && u != vr && vertStamp_[VIndex(*u)] == stamp_)
        return Refuse(OpRefusal::Topology), false;
    }

  // Position of the survivor.
  Point p = Pos(vk);
  int footK = foot_[VIndex(*vk)];
  CoordType stored = vk->cP();
  if (survivorMoves) {
    const SurfaceProjection proj = ref_.Project((Pos(v0) + Pos(v1)) * 0.5, foot_[VIndex(*v0)], scratch_);
    if (!proj.ok()) return Refuse(OpRefusal::Degenerate), false;
    stored = ToCoord(proj.point);
    p = ToPoint(stored);
    footK = proj.face;
  }

  // The faces after the collapse: both stars minus f and g, vr replaced by vk at p.
  oldFaces_.clear();
  newFaces_.clear();
  for (const auto* star : {&starR, &starK})
    for (const auto& [face, k] : *star)
      if (faceStamp_[FIndex(*face)] != stamp_) {
        faceStamp_[FIndex(*face)] = stamp_;
        oldFaces_.push_back(face);
      }
  for (const auto* star : {&starR, &starK})
    for (const auto& [face, k] : *star) {
      if (face == f || face == g) continue;
      NewFace nf;
      for (int j = 0; j < 3; ++j) {
        const VertexPointer u = face->V(j);
        const bool moved = u == vr || u == vk;
        nf.v[j] = moved ? vk : u;
        nf.p[j] = moved ? p : Pos(u);
        nf.foot[j] = moved ? footK : foot_[VIndex(*u)];
        nf.outside[j] = nullptr;
      }
      const int opposite = (k + 1) % 3;
      FacePointer o = face->FFp(opposite);
      if (o != face && faceStamp_[FIndex(*o)] != stamp_) nf.outside[opposite] = o;
      newFaces_.push_back(nf);
    }
  const OpRefusal r = CheckRegion(maxNewEdgeLength, vk);
  if (r != OpRefusal::None) return Refuse(r), false;

  ApplyCollapse(f, z, g, w, vr, vk, stored, footK);
  ++stats_.collapses;
  lastRefusal_ = OpRefusal::None;
  return true;
}

} // namespace molremesh
