// LocalRemeshingOps: the pool of deleted vertices and faces that the operations recycle, and the
// per-element arrays that grow with it.
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
void LocalRemeshingOps<MeshType>::GrowPerElementArrays() {
  ResizeWithSlack(foot_, m_.vert.size(), -1);
  ResizeWithSlack(batchIndex_, m_.vert.size(), -1);
  ResizeWithSlack(locked_, m_.vert.size(), std::uint8_t(0));
  ResizeWithSlack(vertStamp_, m_.vert.size(), std::uint32_t(0));
  ResizeWithSlack(faceStamp_, m_.face.size(), std::uint32_t(0));
  grid_.Resize(m_.face.size());
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::EnsureFree(std::size_t nv, std::size_t nf, FacePointer& f) {
  if (freeVerts_.size() < nv) {
    const std::size_t grow = std::max<std::size_t>({nv, 64, m_.vert.size() / 8});
    const std::size_t first = m_.vert.size();
    // Grown by an eighth, not doubled by std::vector: the pool is the whole mesh's vectors.
    typename ElementCapacity<MeshType>::template Updater<VertexPointer> vu;
    ElementCapacity<MeshType>::ReserveVertices(m_, first + grow, vu);
    vcg::tri::Allocator<MeshType>::AddVertices(m_, grow);
    for (std::size_t i = m_.vert.size(); i-- > first;) {
      vcg::tri::Allocator<MeshType>::DeleteVertex(m_, m_.vert[i]);
      freeVerts_.push_back(i);
    }
  }
  if (freeFaces_.size() < nf) {
    const std::size_t grow = std::max<std::size_t>({nf, 64, m_.face.size() / 8});
    const std::size_t first = m_.face.size();
    typename ElementCapacity<MeshType>::template Updater<FacePointer> pu;
    ElementCapacity<MeshType>::ReserveFaces(m_, first + grow, pu);
    if (pu.NeedUpdate()) pu.Update(f);
    vcg::tri::Allocator<MeshType>::AddFaces(m_, grow);
    for (std::size_t i = m_.face.size(); i-- > first;) {
      vcg::tri::Allocator<MeshType>::DeleteFace(m_, m_.face[i]);
      freeFaces_.push_back(i);
    }
  }
  GrowPerElementArrays();
}

template <class MeshType>
typename MeshType::VertexPointer LocalRemeshingOps<MeshType>::TakeFreeVertex() {
  VertexType& v = m_.vert[freeVerts_.back()];
  freeVerts_.pop_back();
  v.ClearD();
  ++m_.vn;
  return &v;
}

template <class MeshType>
typename MeshType::FacePointer LocalRemeshingOps<MeshType>::TakeFreeFace() {
  FaceType& f = m_.face[freeFaces_.back()];
  freeFaces_.pop_back();
  f.ClearD();
  ++m_.fn;
  return &f;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Release(FaceType& f) {
  grid_.Remove(FIndex(f));
  vcg::tri::Allocator<MeshType>::DeleteFace(m_, f);
  freeFaces_.push_back(FIndex(f));
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Release(VertexType& v) {
  vcg::tri::Allocator<MeshType>::DeleteVertex(m_, v);
  v.VFp() = nullptr;
  v.VFi() = -1;
  locked_[VIndex(v)] = 0;
  freeVerts_.push_back(VIndex(v));
}

} // namespace molremesh
