// LocalRemeshingOps: read-only queries on the mesh (vertex star, boundary, valence, edge lookup,
// Delaunay and valence criteria of a flip).
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
bool LocalRemeshingOps<MeshType>::GatherStar(const VertexType* v,
                                             std::vector<std::pair<FacePointer, int>>& star) const {
  star.clear();
  bool boundary = false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(v)); !it.End(); ++it) {
    star.emplace_back(it.F(), it.I());
    if (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3)) boundary = true;
  }
  return boundary;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::IsBoundaryVertex(const VertexType& v) const {
  if (!hasBorder_ || v.cVFp() == nullptr) return false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it)
    if (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3)) return true;
  return false;
}

template <class MeshType>
int LocalRemeshingOps<MeshType>::Valence(const VertexType& v) const {
  if (v.cVFp() == nullptr) return 0;
  int faces = 0;
  bool boundary = false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
    ++faces;
    if (hasBorder_ && (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3))) boundary = true;
  }
  return boundary ? faces + 1 : faces;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::FindEdge(VertexPointer a, VertexPointer b, FacePointer& f, int& z) const {
  if (a->VFp() == nullptr) return false;
  for (vcg::face::VFIterator<FaceType> it(a); !it.End(); ++it) {
    const int k = it.I();
    if (it.F()->V((k + 1) % 3) == b) {
      f = it.F();
      z = k;
      return true;
    }
    if (it.F()->V((k + 2) % 3) == b) {
      f = it.F();
      z = (k + 2) % 3;
      return true;
    }
  }
  return false;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::IsDelaunay(const FaceType& f, int z) const {
  if (IsBorder(f, z)) return true;
  const FaceType& g = *f.cFFp(z);
  const int w = f.cFFi(z);
  // cot(alpha) + cot(beta) >= 0  <=>  alpha + beta <= pi
  auto cot = [&](const Point& apex, const Point& a, const Point& b) {
    const Point u = a - apex, v = b - apex;
    const double s = (u ^ v).Norm();
    return s > 0 ? (u * v) / s : std::numeric_limits<double>::infinity() * ((u * v) >= 0 ? 1 : -1);
  };
  const Point a = Pos(f.cV(z)), b = Pos(f.cV((z + 1) % 3));
  const double sum = cot(Pos(f.cV((z + 2) % 3)), a, b) + cot(Pos(g.cV((w + 2) % 3)), a, b);
  return !(sum < -1e-12);
}

template <class MeshType>
int LocalRemeshingOps<MeshType>::FlipValenceGain(const FaceType& f, int z) const {
  if (IsBorder(f, z)) return 0;
  const FaceType& g = *f.cFFp(z);
  const int w = f.cFFi(z);
  const std::array<const VertexType*, 4> v{f.cV(z), f.cV((z + 1) % 3), f.cV((z + 2) % 3), g.cV((w + 2) % 3)};
  const std::array<int, 4> change{-1, -1, +1, +1};
  int before = 0, after = 0;
  for (int i = 0; i < 4; ++i) {
    const int valence = Valence(*v[i]);
    const int ideal = IsBoundaryVertex(*v[i]) ? 4 : 6;
    before += std::abs(valence - ideal);
    after += std::abs(valence + change[i] - ideal);
  }
  return before - after;
}

} // namespace molremesh
