// LocalRemeshingOps: guarded relocation of one vertex on the reference surface.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
bool LocalRemeshingOps<MeshType>::RelocateVertex(VertexPointer v, const Point& target) {
  const SurfaceProjection proj = ref_.Project(target, foot_[VIndex(*v)], scratch_);
  if (!proj.ok()) {
    Refuse(OpRefusal::Degenerate);
    return false;
  }
  return MoveVertexTo(v, proj.point, proj.face);
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::MoveVertexTo(VertexPointer v, const Point& onSurface, int footFace) {
  if (HasPendingMoves()) VerifyPendingMoves();
  const std::size_t vi = VIndex(*v);
  if (locked_[vi]) return Refuse(OpRefusal::Locked), false;
  if (v->VFp() == nullptr) return Refuse(OpRefusal::Topology), false;
  if (GatherStar(v, star0_)) return Refuse(OpRefusal::Boundary), false;
  // Checked at the position the mesh can store (float meshes round it).
  const CoordType stored = ToCoord(onSurface);
  const Point p = ToPoint(stored);

  NewStamp();
  oldFaces_.clear();
  newFaces_.clear();
  for (const auto& [f, z] : star0_) {
    faceStamp_[FIndex(*f)] = stamp_;
    oldFaces_.push_back(f);
  }
  for (const auto& [f, z] : star0_) {
    NewFace nf;
    for (int k = 0; k < 3; ++k) {
      nf.v[k] = f->V(k);
      nf.p[k] = k == z ? p : Pos(f->V(k));
      nf.foot[k] = k == z ? footFace : foot_[VIndex(*f->V(k))];
      nf.outside[k] = nullptr;
    }
    const int opposite = (z + 1) % 3;
    FacePointer g = f->FFp(opposite);
    if (g != f && faceStamp_[FIndex(*g)] != stamp_) nf.outside[opposite] = g;
    newFaces_.push_back(nf);
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  v->P() = stored;
  foot_[vi] = footFace;
  for (std::size_t i = 0; i < star0_.size(); ++i)
    grid_.Update(FIndex(*star0_[i].first), FaceBox(*star0_[i].first));
  ++stats_.moves;
  lastRefusal_ = OpRefusal::None;
  return true;
}

} // namespace molremesh
