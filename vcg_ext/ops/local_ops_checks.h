// LocalRemeshingOps: the guards every operation runs on the faces it would produce (angles, area,
// normals, folds, intersections, fidelity to the input).
//
// Part of LocalRemeshingOps (vcg_ext/ops/local_remeshing_ops.h, which includes it after the class).
#pragma once

namespace molremesh {

template <class MeshType>
void LocalRemeshingOps<MeshType>::AngleCosines(const Point& a, const Point& b, const Point& c, double& cosMin,
                                               double& cosMax) {
  // Squared edge lengths opposite each corner; the smallest angle faces the shortest edge and the
  // largest angle the longest one (law of cosines, no trigonometry).
  const double la = (b - c).SquaredNorm(), lb = (c - a).SquaredNorm(), lc = (a - b).SquaredNorm();
  auto cosAt = [](double opposite, double s1, double s2) {
    const double d = 2.0 * std::sqrt(s1 * s2);
    return d > 0 ? std::clamp((s1 + s2 - opposite) / d, -1.0, 1.0) : 1.0;
  };
  double lo = la, hi = la;
  int iLo = 0, iHi = 0;
  if (lb < lo) lo = lb, iLo = 1;
  if (lc < lo) lo = lc, iLo = 2;
  if (lb > hi) hi = lb, iHi = 1;
  if (lc > hi) hi = lc, iHi = 2;
  const std::array<double, 3> l{la, lb, lc};
  cosMin = cosAt(l[iLo], l[(iLo + 1) % 3], l[(iLo + 2) % 3]);
  cosMax = cosAt(l[iHi], l[(iHi + 1) % 3], l[(iHi + 2) % 3]);
}

template <class MeshType>
typename LocalRemeshingOps<MeshType>::RegionMetrics LocalRemeshingOps<MeshType>::OldMetrics() const {
  RegionMetrics r;
  for (const FacePointer f : oldFaces_) {
    const Point a = Pos(f->cV(0)), b = Pos(f->cV(1)), c = Pos(f->cV(2));
    double cmin, cmax;
    AngleCosines(a, b, c, cmin, cmax);
    r.cosMinAngle = std::max(r.cosMinAngle, cmin);
    r.cosMaxAngle = std::min(r.cosMaxAngle, cmax);
    r.smallFaces += cmin > cosMinAngleGuard_;
    r.largeFaces += cmax < cosMaxAngleGuard_;
    const Point n = FaceNormal(*f);
    const std::array<int, 3> feet{foot_[VIndex(*f->cV(0))], foot_[VIndex(*f->cV(1))],
                                  foot_[VIndex(*f->cV(2))]};
    const Point s = RefNormalSum(feet);
    const double len = s.Norm();
    r.cosNormal = std::min(r.cosNormal, len > 1e-12 ? (n * s) / len : -1.0);
    for (int e = 0; e < 3; ++e)
      if (!IsBorder(*f, e)) r.cosFold = std::min(r.cosFold, n * FaceNormal(*f->cFFp(e)));
  }
  return r;
}

template <class MeshType>
OpRefusal LocalRemeshingOps<MeshType>::CheckRegion(double maxEdgeLength, const VertexType* lengthVertex) {
  const std::size_t n = newFaces_.size();
  RegionMetrics nm;
  for (std::size_t i = 0; i < n; ++i) {
    NewFace& nf = newFaces_[i];
    const Point cross = (nf.p[1] - nf.p[0]) ^ (nf.p[2] - nf.p[0]);
    const double area2 = cross.SquaredNorm();
    if (!(area2 > minArea2_)) return OpRefusal::Degenerate;
    nf.n = cross / std::sqrt(area2);
    nf.box.SetNull();
    for (int k = 0; k < 3; ++k) nf.box.Add(nf.p[k]);
    double cmin, cmax;
    AngleCosines(nf.p[0], nf.p[1], nf.p[2], cmin, cmax);
    nm.cosMinAngle = std::max(nm.cosMinAngle, cmin);
    nm.cosMaxAngle = std::min(nm.cosMaxAngle, cmax);
    nm.smallFaces += cmin > cosMinAngleGuard_;
    nm.largeFaces += cmax < cosMaxAngleGuard_;
    const Point s = RefNormalSum(nf.foot);
    const double len = s.Norm();
    nm.cosNormal = std::min(nm.cosNormal, len > 1e-12 ? (nf.n * s) / len : -1.0);
  }
  if (lengthVertex != nullptr && maxEdgeLength < std::numeric_limits<double>::infinity()) {
    const double max2 = maxEdgeLength * maxEdgeLength;
    for (const NewFace& nf : newFaces_)
      for (int k = 0; k < 3; ++k)
        if (nf.v[k] == lengthVertex)
          for (int j = 1; j < 3; ++j)
            if ((nf.p[(k + j) % 3] - nf.p[k]).SquaredNorm() > max2) return OpRefusal::EdgeLength;
  }
  // Internal adjacency among the new faces and fold angles.
  for (std::size_t i = 0; i < n; ++i) {
    NewFace& nf = newFaces_[i];
    for (int e = 0; e < 3; ++e) {
      nf.internal[e] = -1;
      const VertexPointer a = nf.v[e], b = nf.v[(e + 1) % 3];
      for (std::size_t j = 0; j < n && nf.internal[e] < 0; ++j) {
        if (j == i) continue;
        const NewFace& o = newFaces_[j];
        for (int k = 0; k < 3; ++k)
          if (o.v[k] == b && o.v[(k + 1) % 3] == a) {
            nf.internal[e] = int(j);
            break;
          }
      }
      if (nf.internal[e] >= 0)
        nm.cosFold = std::min(nm.cosFold, nf.n * newFaces_[nf.internal[e]].n);
      else if (nf.outside[e] != nullptr)
        nm.cosFold = std::min(nm.cosFold, nf.n * FaceNormal(*nf.outside[e]));
    }
  }
  const bool minOk = nm.cosMinAngle <= cosMinAngleGuard_;
  const bool maxOk = nm.cosMaxAngle >= cosMaxAngleGuard_;
  const bool normalOk = nm.cosNormal >= cosNormalGuard_;
  const bool foldOk = nm.cosFold >= cosFoldGuard_;
  if (!(minOk && maxOk && normalOk && foldOk)) {
    const RegionMetrics om = OldMetrics();
    if (!minOk && !(nm.cosMinAngle < om.cosMinAngle)) return OpRefusal::MinAngle;
    if (!maxOk && !(nm.cosMaxAngle > om.cosMaxAngle)) return OpRefusal::MaxAngle;
    if (!normalOk && !(nm.cosNormal >= om.cosNormal)) return OpRefusal::Normal;
    if (!foldOk && !(nm.cosFold >= om.cosFold)) return OpRefusal::Fold;
  }
  if (guards_.noMoreBadFaces && (!minOk || !maxOk)) {
    const RegionMetrics om = OldMetrics();
    if (nm.smallFaces > om.smallFaces) return OpRefusal::MinAngle;
    if (nm.largeFaces > om.largeFaces) return OpRefusal::MaxAngle;
  }
  if (guards_.checkIntersections && NewFacesIntersect()) return OpRefusal::Intersection;
  if (guards_.maxInputDistanceFactor > 0 && NewFacesLeaveInput()) return OpRefusal::InputDistance;
  return OpRefusal::None;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::NewFacesLeaveInput() {
  using reference_detail::ClosestPointOnTriangle;
  const double tol = guards_.maxInputDistanceFactor * L_;
  const double tol2 = tol * tol;
  const double reach = std::max(tol, guards_.inputReachFactor * L_);
  vcg::Box3d box;
  for (const FacePointer f : oldFaces_)
    for (int k = 0; k < 3; ++k) box.Add(Pos(f->cV(k)));
  for (const NewFace& nf : newFaces_)
    for (int k = 0; k < 3; ++k) box.Add(nf.p[k]);
  box.Offset(reach);
  auto distance2 = [](const Point& q, const Point& a, const Point& b, const Point& c) {
    return (ClosestPointOnTriangle(q, a, b, c) - q).SquaredNorm();
  };
  // Whether q ends farther than tol from the mesh and farther than it was.
  auto worse = [&](const Point& q) {
    double new2 = std::numeric_limits<double>::infinity();
    for (const NewFace& nf : newFaces_) {
      new2 = std::min(new2, distance2(q, nf.p[0], nf.p[1], nf.p[2]));
      if (new2 <= tol2) return false;
    }
    double old2 = std::numeric_limits<double>::infinity();
    for (const FacePointer f : oldFaces_)
      old2 = std::min(old2, distance2(q, Pos(f->cV(0)), Pos(f->cV(1)), Pos(f->cV(2))));
    if (new2 <= old2) return false;
    // The rest of the mesh (unchanged) may hold q closer than the new faces.
    const double r = std::sqrt(new2);
    double rest2 = new2;
    grid_.Query(vcg::Box3d(q - Point(r, r, r), q + Point(r, r, r)), [&](std::size_t g) {
      if (faceStamp_[g] == stamp_ || rest2 <= tol2) return;
      const FaceType& face = m_.face[g];
      rest2 = std::min(rest2, distance2(q, Pos(face.cV(0)), Pos(face.cV(1)), Pos(face.cV(2))));
    });
    return rest2 > tol2 && rest2 > old2;
  };
  bool leaves = false;
  ref_.ForEachFaceInBox(box, inputScratch_, [&](int f) {
    if (leaves) return;
    // The centroid and the points halfway between it and the corners: on a face across a ridge
    // of the input, the farthest point is inside, not at a corner.
    const Point &a = ref_.Corner(f, 0), &b = ref_.Corner(f, 1), &c = ref_.Corner(f, 2);
    const Point centroid = (a + b + c) / 3.0;
    for (const Point& q : {centroid, (centroid + a) * 0.5, (centroid + b) * 0.5, (centroid + c) * 0.5})
      if (box.IsIn(q) && worse(q)) {
        leaves = true;
        return;
      }
    for (int k = 0; k < 3 && !leaves; ++k) {
      const std::uint32_t vi = ref_.FaceVertices(f)[k];
      if (ref_.VertexFace(vi) == f && box.IsIn(ref_.Vertex(vi)) && worse(ref_.Vertex(vi))) leaves = true;
    }
  });
  return leaves;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::StarPairs(
    const TrianglePairScan& scan, int threads,
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) const {
  threads = ResolveThreadCount(threads);
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(static_cast<std::size_t>(threads));
  ParallelFor(m_.vert.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    std::vector<std::uint32_t> star;
    std::vector<std::pair<Point, Point>> link;
    for (std::size_t vi = begin; vi < end; ++vi) {
      const VertexType& v = m_.vert[vi];
      if (v.IsD() || v.cVFp() == nullptr) continue;
      star.clear();
      link.clear();
      bool boundary = false, moved = false;
      for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
        const int k = it.I();
        star.push_back(std::uint32_t(FIndex(*it.F())));
        // The corners as the scan collected them: no vertex record to read.
        link.emplace_back(scan.Corner(star.back(), (k + 1) % 3), scan.Corner(star.back(), (k + 2) % 3));
        if (IsBorder(*it.F(), k) || IsBorder(*it.F(), (k + 2) % 3)) boundary = true;
        if (scan.Input(star.back()).moved) moved = true;
      }
      if (!moved) continue;
      if (local_ops_detail::StarIsSimpleFan(Pos(&v), link.data(), int(link.size()), boundary)) continue;
      for (std::size_t i = 0; i < star.size(); ++i)
        for (std::size_t j = i + 1; j < star.size(); ++j) {
          const TrianglePairScan::Triangle &a = scan.Input(star[i]), &b = scan.Input(star[j]);
          if (!a.moved && !b.moved) continue;
          int shared = 0;
          for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y) shared += a.v[x] == b.v[y] ? 1 : 0;
          if (shared != 1) continue;
          if (!local_ops_detail::FacesIntersect(scan.Corners(star[i]), scan.Normal(star[i]), a.v,
                                                scan.Corners(star[j]), scan.Normal(star[j]), b.v, margin_))
            continue;
          found[std::size_t(t)].emplace_back(std::min(star[i], star[j]), std::max(star[i], star[j]));
        }
    }
  });
  for (const auto& list : found) pairs.insert(pairs.end(), list.begin(), list.end());
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::NewFacesIntersect() {
  using local_ops_detail::FacesIntersect;
  const std::size_t n = newFaces_.size();
  vcg::Box3d all;
  for (std::size_t i = 0; i < n; ++i) {
    newFaces_[i].box.Offset(tol_);
    all.Add(newFaces_[i].box);
  }
  // Against the faces outside the region (the region's old faces carry the current stamp).
  candidates_.clear();
  grid_.Query(all, [&](std::size_t g) {
    if (faceStamp_[g] != stamp_) candidates_.push_back(g);
  });
  for (const std::size_t gi : candidates_) {
    const FaceType& g = m_.face[gi];
    const vcg::Box3d gbox = grid_.BoxOf(gi);
    bool built = false;
    std::array<Point, 3> gp;
    std::array<VertexPointer, 3> gv{};
    Point gn;
    for (std::size_t i = 0; i < n; ++i) {
      const NewFace& nf = newFaces_[i];
      if (!FaceHashGrid::Touch(nf.box, gbox)) continue;
      if (!built) {
        for (int k = 0; k < 3; ++k) {
          gv[k] = const_cast<VertexPointer>(g.cV(k));
          gp[k] = Pos(g.cV(k));
        }
        gn = local_ops_detail::UnitNormal(gp);
        built = true;
      }
      if (FacesIntersect(nf.p, nf.n, nf.v, gp, gn, gv, margin_)) return true;
    }
  }
  // Among the new faces.
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const NewFace& a = newFaces_[i];
      const NewFace& b = newFaces_[j];
      if (FaceHashGrid::Touch(a.box, b.box) && FacesIntersect(a.p, a.n, a.v, b.p, b.n, b.v, margin_))
        return true;
    }
  return false;
}

} // namespace molremesh
