// LocalRemeshingOps: guarded edge flip.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
bool LocalRemeshingOps<MeshType>::FlipEdge(FacePointer f, int z) {
  if (HasPendingMoves()) VerifyPendingMoves();
  if (IsBorder(*f, z)) return Refuse(OpRefusal::Boundary), false;
  FacePointer g = f->FFp(z);
  const int w = f->FFi(z);
  const VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3), v2 = f->V((z + 2) % 3), v3 = g->V((w + 2) % 3);
  if ((locked_[VIndex(*v0)] && locked_[VIndex(*v1)]) || (locked_[VIndex(*v2)] && locked_[VIndex(*v3)]))
    return Refuse(OpRefusal::Locked), false;
  if (v2 == v3) return Refuse(OpRefusal::Topology), false;
  for (const VertexPointer u : {v0, v1})
    if (Valence(*u) <= (IsBoundaryVertex(*u) ? 2 : 3)) return Refuse(OpRefusal::Topology), false;
  for (vcg::face::VFIterator<FaceType> it(v2); !it.End(); ++it)
    if (it.F()->V((it.I() + 1) % 3) == v3 || it.F()->V((it.I() + 2) % 3) == v3)
      return Refuse(OpRefusal::Topology), false;

  NewStamp();
  faceStamp_[FIndex(*f)] = stamp_;
  faceStamp_[FIndex(*g)] = stamp_;
  oldFaces_.clear();
  oldFaces_.push_back(f);
  oldFaces_.push_back(g);
  newFaces_.clear();
  auto outside = [&](FacePointer face, int e) -> FacePointer {
    FacePointer o = face->FFp(e);
    return (o == face || faceStamp_[FIndex(*o)] == stamp_) ? nullptr : o;
  };
  auto make = [&](VertexPointer a, VertexPointer b, VertexPointer c, FacePointer outAB, FacePointer outBC,
                  FacePointer outCA) {
    NewFace nf;
    nf.v = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      nf.p[k] = Pos(nf.v[k]);
      nf.foot[k] = foot_[VIndex(*nf.v[k])];
    }
    nf.outside = {outAB, outBC, outCA};
    newFaces_.push_back(nf);
  };
  make(v0, v3, v2, outside(g, (w + 1) % 3), nullptr, outside(f, (z + 2) % 3));
  make(v1, v2, v3, outside(f, (z + 1) % 3), nullptr, outside(g, (w + 2) % 3));
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  const int z1 = (z + 1) % 3, w1 = (w + 1) % 3;
  FacePointer fa = f->FFp(z1);
  const int ia = f->FFi(z1);
  FacePointer gb = g->FFp(w1);
  const int ib = g->FFi(w1);
  vcg::face::VFDetach(*f, z1); // v1 leaves f
  vcg::face::VFDetach(*g, w1); // v0 leaves g
  f->V(z1) = v3;
  g->V(w1) = v2;
  // f = (v0, v3, v2): edge z = (v0, v3) takes g's old (v0, v3) neighbour.
  if (gb == g) {
    f->FFp(z) = f;
    f->FFi(z) = z;
  } else {
    f->FFp(z) = gb;
    f->FFi(z) = ib;
    gb->FFp(ib) = f;
    gb->FFi(ib) = z;
  }
  // g = (v1, v2, v3): edge w = (v1, v2) takes f's old (v1, v2) neighbour.
  if (fa == f) {
    g->FFp(w) = g;
    g->FFi(w) = w;
  } else {
    g->FFp(w) = fa;
    g->FFi(w) = ia;
    fa->FFp(ia) = g;
    fa->FFi(ia) = w;
  }
  f->FFp(z1) = g;
  f->FFi(z1) = w1;
  g->FFp(w1) = f;
  g->FFi(w1) = z1;
  VFAppend(f, z1);
  VFAppend(g, w1);
  grid_.Update(FIndex(*f), FaceBox(*f));
  grid_.Update(FIndex(*g), FaceBox(*g));
  ++stats_.flips;
  lastRefusal_ = OpRefusal::None;
  return true;
}

} // namespace molremesh
