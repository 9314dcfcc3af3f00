// Ray intersection with functional objects through ray queries.
//
// F'(p) = F(p) + Σ f_i max(Q_i(p), 0)³ (NOTES.md eq. 1-2), inside where F' >= 0.
// Each candidate AABB is a cell of one object that lists the perturbations
// that can be non-zero in it. Along the ray inside the cell, F and each Q_i
// are quadratics in t; the roots of the Q_i cut the segment into pieces on
// which F' is a polynomial of degree <= 6, whose first root is isolated
// exactly (roots.glsl). The f64 twin is src/model/geometry/reference.rs.
#ifndef INTERSECT_GLSL
#define INTERSECT_GLSL

#include "interface.glsl"
#include "roots.glsl"
// INTERSECT_MODE (cost breakdowns: the whole search, the boxes alone, the
// base quadric alone) and FAR_RAYS.
#include "spec_constants.glsl"

// The parts, each one concept:
#include "quadric.glsl"
#include "root_search.glsl"
#include "derivatives.glsl"
#include "hit.glsl"
#ifdef RAY_TRACING_PIPELINE
#include "traverse_pipeline.glsl"
#else
#include "traverse.glsl"
#endif

#endif
