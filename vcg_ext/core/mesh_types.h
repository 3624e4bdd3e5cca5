// Mesh types used by the command-line tool and the tests.
//
// The algorithms in vcg_ext/ are templates and also run on MeshLab's CMeshO (float); the CLI
// uses double precision coordinates because the remeshing stages compare small angles and
// distances that float cannot resolve on large molecules.
#pragma once

#include <vcg/complex/complex.h>

namespace molremesh {

class VertexD;
class FaceD;
struct UsedTypesD : public vcg::UsedTypes<vcg::Use<VertexD>::AsVertexType, vcg::Use<FaceD>::AsFaceType> {};

class VertexD : public vcg::Vertex<UsedTypesD, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                   vcg::vertex::Color4b, vcg::vertex::Qualityd, vcg::vertex::BitFlags,
                                   vcg::vertex::VFAdj, vcg::vertex::Mark> {};

class FaceD : public vcg::Face<UsedTypesD, vcg::face::VertexRef, vcg::face::Normal3d, vcg::face::Color4b,
                               vcg::face::Qualityd, vcg::face::BitFlags, vcg::face::FFAdj, vcg::face::VFAdj,
                               vcg::face::Mark> {};

/// Triangle mesh with double coordinates, per-element color/quality/normal and FF/VF adjacency.
class MeshD : public vcg::tri::TriMesh<std::vector<VertexD>, std::vector<FaceD>> {};

} // namespace molremesh
