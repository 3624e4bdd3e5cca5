// Exact capacity of a vcg mesh's vertex and face vectors.
//
// vcg::tri::Allocator grows the element vectors with std::vector::resize, which doubles the
// capacity whenever it runs out: a mesh that grew by one face past a power of two holds room for
// twice its faces, for the rest of its life (clear() keeps the capacity too). On a 535k-face
// input that is 70 MB of faces and 25 MB of vertices never used, per mesh. These functions
// reallocate a vector to a given capacity and repair every pointer into it the way vcg's own
// allocation does (faces' vertex references, face-face and vertex-face adjacency), so a caller
// can grow in steps of its choosing and give back what a stage no longer needs.
//
// Preconditions: a triangle mesh without edges, half-edges or tetrahedra (the meshes of
// vcg_ext), whose element containers have reserve() and shrink_to_fit() (std::vector).
#pragma once

#include <vcg/complex/complex.h>

#include <cstddef>

namespace molremesh {

template <class MeshType>
class ElementCapacity {
public:
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  template <class P>
  using Updater = typename vcg::tri::Allocator<MeshType>::template PointerUpdater<P>;

  /// Makes room for at least `capacity` vertices without a doubling; pu says how pointers moved.
  static void ReserveVertices(MeshType& m, std::size_t capacity, Updater<VertexPointer>& pu) {
    pu.Clear();
    if (m.vert.capacity() < capacity) ChangeVertices(m, pu, [&] { m.vert.reserve(capacity); });
  }

  /// Makes room for at least `capacity` faces without a doubling; pu says how pointers moved.
  static void ReserveFaces(MeshType& m, std::size_t capacity, Updater<FacePointer>& pu) {
    pu.Clear();
    if (m.face.capacity() < capacity) ChangeFaces(m, pu, [&] { m.face.reserve(capacity); });
  }

  /// Gives back the capacity beyond the elements' count when it exceeds it by more than
  /// 1/slackDivisor (a reallocation costs a copy of the vector; a small excess is not worth it).
  static void ShrinkToFit(MeshType& m, std::size_t slackDivisor = 8) {
    Updater<VertexPointer> vertexUpdate;
    if (m.vert.capacity() > m.vert.size() + m.vert.size() / slackDivisor)
      ChangeVertices(m, vertexUpdate, [&] { m.vert.shrink_to_fit(); });
    Updater<FacePointer> faceUpdate;
    if (m.face.capacity() > m.face.size() + m.face.size() / slackDivisor)
      ChangeFaces(m, faceUpdate, [&] { m.face.shrink_to_fit(); });
  }

private:
  template <class Change>
  static void ChangeVertices(MeshType& m, Updater<VertexPointer>& pu, Change change) {
    Reallocate(m.vert, pu, change);
    if (pu.NeedUpdate()) UpdateVertexPointers(m, pu);
  }

  template <class Change>
  static void ChangeFaces(MeshType& m, Updater<FacePointer>& pu, Change change) {
    Reallocate(m.face, pu, change);
    if (pu.NeedUpdate()) UpdateFacePointers(m, pu);
  }

  template <class Container, class Pointer, class Change>
  static void Reallocate(Container& elements, Updater<Pointer>& pu, Change change) {
    if (elements.empty()) {
      change(); // nothing points into an empty vector
      return;
    }
    pu.oldBase = &*elements.begin();
    pu.oldEnd = &elements.back() + 1;
    change();
    pu.newBase = &*elements.begin();
    pu.newEnd = &elements.back() + 1;
  }

  static void UpdateVertexPointers(MeshType& m, Updater<VertexPointer>& pu) {
    for (auto& f : m.face)
      if (!f.IsD())
        for (int k = 0; k < f.VN(); ++k)
          if (f.cV(k) != nullptr) pu.Update(f.V(k));
  }

  static void UpdateFacePointers(MeshType& m, Updater<FacePointer>& pu) {
    for (auto& f : m.face) {
      if (f.IsD()) continue;
      if (vcg::tri::HasFFAdjacency(m))
        for (int k = 0; k < f.VN(); ++k)
          if (f.cFFp(k) != nullptr) pu.Update(f.FFp(k));
      if (vcg::tri::HasPerFaceVFAdjacency(m) && vcg::tri::HasPerVertexVFAdjacency(m))
        for (int k = 0; k < f.VN(); ++k)
          if (f.cVFp(k) != nullptr) pu.Update(f.VFp(k));
    }
    if (vcg::tri::HasPerFaceVFAdjacency(m) && vcg::tri::HasPerVertexVFAdjacency(m))
      for (auto& v : m.vert)
        if (!v.IsD() && v.cVFp() != nullptr) pu.Update(v.VFp());
  }
};

} // namespace molremesh
