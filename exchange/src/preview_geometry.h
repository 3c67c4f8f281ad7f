#pragma once
// The preview's two objects (weft export -o X.html), made here so that the page needs no model
// files: a cushion (a rounded, puffed box) and a cloth draped over a sphere, hanging in folds.
// Both are seen from every side, so both show the material at every angle a cloth meets.
#include "gltf_asset.h"

namespace weft::gltf_detail {

// A cushion 'width_m' square and 'thickness_m' thick at its middle, thinner towards its edges,
// resting on y = 0.
GltfMesh cushion_mesh(double width_m = 0.5, double thickness_m = 0.2, int segments = 48);

// A square sheet 'side_m' wide laid over a sphere of 'radius_m' whose top is at 'top_m': on the
// sphere up to 'contact_rad' from its top, then hanging along the tangent, folded radially.
GltfMesh drape_mesh(double side_m = 1.3, double radius_m = 0.28, double top_m = 0.75,
                    double contact_rad = 1.1, int segments = 96);

// Vertex normals: the area-weighted normals of the faces around each position, welded by
// position so that a seam (duplicated vertices of one point) shades smoothly.
void smooth_normals(GltfMesh& mesh);

}  // namespace weft::gltf_detail
