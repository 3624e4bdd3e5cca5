// LocalRemeshingOps: guarded edge split.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
typename MeshType::FacePointer LocalRemeshingOps<MeshType>::SplitOffFace(FacePointer f, int z,
                                                                         VertexPointer mv, VertexPointer b,
                                                                         VertexPointer c) {
  const int z1 = (z + 1) % 3;
  FacePointer fa = f->FFp(z1);
  const int ia = f->FFi(z1);
  const FacePointer f2 = TakeFreeFace();
  f2->ImportData(*f);
  vcg::face::VFDetach(*f, z1);
  f->V(z1) = mv;
  f2->V(0) = mv;
  f2->V(1) = b;
  f2->V(2) = c;
  f->FFp(z1) = f2;
  f->FFi(z1) = 2;
  f2->FFp(2) = f;
  f2->FFi(2) = z1;
  if (fa == f) {
    f2->FFp(1) = f2;
    f2->FFi(1) = 1;
  } else {
    f2->FFp(1) = fa;
    f2->FFi(1) = ia;
    fa->FFp(ia) = f2;
    fa->FFi(ia) = 1;
  }
  return f2;
}

template <class MeshType>
typename MeshType::VertexPointer LocalRemeshingOps<MeshType>::SplitEdge(FacePointer f, int z) {
  if (HasPendingMoves()) VerifyPendingMoves();
  EnsureFree(1, 2, f);
  const bool border = IsBorder(*f, z);
  const VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3), v2 = f->V((z + 2) % 3);
  if (locked_[VIndex(*v0)] && locked_[VIndex(*v1)]) return Refuse(OpRefusal::Locked), nullptr;
  FacePointer g = border ? nullptr : f->FFp(z);
  const int w = border ? -1 : f->FFi(z);
  const VertexPointer v3 = border ? nullptr : g->V((w + 2) % 3);
  if (!border && v3 == v2) return Refuse(OpRefusal::Topology), nullptr;

  const SurfaceProjection proj = ref_.Project((Pos(v0) + Pos(v1)) * 0.5, foot_[VIndex(*v0)], scratch_);
  if (!proj.ok()) return Refuse(OpRefusal::Degenerate), nullptr;
  const CoordType stored = ToCoord(proj.point);
  const Point p = ToPoint(stored);
  const VertexPointer nv = &m_.vert[freeVerts_.back()]; // identity only until applied

  NewStamp();
  oldFaces_.clear();
  newFaces_.clear();
  oldFaces_.push_back(f);
  faceStamp_[FIndex(*f)] = stamp_;
  if (!border) {
    oldFaces_.push_back(g);
    faceStamp_[FIndex(*g)] = stamp_;
  }
  auto make = [&](VertexPointer a, VertexPointer b, VertexPointer c, FacePointer outAB, FacePointer outBC,
                  FacePointer outCA) {
    NewFace nf;
    nf.v = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      nf.p[k] = nf.v[k] == nv ? p : Pos(nf.v[k]);
      nf.foot[k] = nf.v[k] == nv ? proj.face : foot_[VIndex(*nf.v[k])];
    }
    nf.outside = {outAB, outBC, outCA};
    newFaces_.push_back(nf);
  };
  auto outside = [&](FacePointer face, int e) -> FacePointer {
    FacePointer o = face->FFp(e);
    return (o == face || faceStamp_[FIndex(*o)] == stamp_) ? nullptr : o;
  };
  make(v0, nv, v2, nullptr, nullptr, outside(f, (z + 2) % 3)); // f after the split
  make(nv, v1, v2, nullptr, outside(f, (z + 1) % 3), nullptr); // new face f2
  if (!border) {
    make(v1, nv, v3, nullptr, nullptr, outside(g, (w + 2) % 3)); // g after the split
    make(nv, v0, v3, nullptr, outside(g, (w + 1) % 3), nullptr); // new face g2
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), nullptr;

  // Apply.
  const VertexPointer mv = TakeFreeVertex();
  mv->ImportData(*v0);
  mv->P() = stored;
  mv->VFp() = nullptr;
  mv->VFi() = -1;
  foot_[VIndex(*mv)] = proj.face;
  locked_[VIndex(*mv)] = 0;

  const int z1 = (z + 1) % 3;
  const FacePointer f2 = SplitOffFace(f, z, mv, v1, v2);
  FacePointer g2 = nullptr;
  if (border) {
    f->FFp(z) = f;
    f->FFi(z) = z;
    f2->FFp(0) = f2;
    f2->FFi(0) = 0;
  } else {
    g2 = SplitOffFace(g, w, mv, v0, v3);
    f->FFp(z) = g2;
    f->FFi(z) = 0;
    g2->FFp(0) = f;
    g2->FFi(0) = z;
    g->FFp(w) = f2;
    g->FFi(w) = 0;
    f2->FFp(0) = g;
    f2->FFi(0) = w;
  }
  VFAppend(f, z1);
  for (int k = 0; k < 3; ++k) VFAppend(f2, k);
  grid_.Update(FIndex(*f), FaceBox(*f));
  grid_.Insert(FIndex(*f2), FaceBox(*f2));
  if (!border) {
    VFAppend(g, (w + 1) % 3);
    for (int k = 0; k < 3; ++k) VFAppend(g2, k);
    grid_.Update(FIndex(*g), FaceBox(*g));
    grid_.Insert(FIndex(*g2), FaceBox(*g2));
  }
  ++stats_.splits;
  lastRefusal_ = OpRefusal::None;
  return mv;
}

} // namespace molremesh
