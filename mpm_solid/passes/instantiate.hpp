#pragma once
// The kernels Solver's constructor picks from take every pass for every
// dimension and shape: each pass's file instantiates its templates for them
// (a template defined in one file and called from solver.cpp's step).
// EACH(Dim, Shape) over the lot.

#include "mpm_solid/shape.hpp"

#define OUTBURST_MPM_EACH_SHAPE(EACH) \
  EACH(2, Linear)                     \
  EACH(2, Gimp)                       \
  EACH(2, Bspline)                    \
  EACH(3, Linear)                     \
  EACH(3, Gimp)                       \
  EACH(3, Bspline)
