//! B-spline and NURBS curves and surfaces.
