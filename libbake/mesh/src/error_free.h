// error_free.h — error-free transformations of double arithmetic (Knuth's TwoSum, Dekker's
// TwoDiff, FMA's TwoProduct; Shewchuk 1997 §2), private to the mesh module: x is the rounded
// result and y its rounding error exactly (x + y = the exact value). The exact predicates
// (predicates.cpp) build expansions from them; texels.cpp uses y == 0 to know an interpolation
// was exact.
#pragma once

#include <cmath>

namespace prt::bake::error_free {

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}
inline void fast_two_sum(double a, double b, double& x, double& y) {  // |a| >= |b|
  x = a + b;
  y = b - (x - a);
}
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x, av = x + bv;
  y = (a - av) + (bv - b);
}
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

} // namespace prt::bake::error_free
