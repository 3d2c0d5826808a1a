// prtshade/quadrature.h — Gauss–Legendre quadrature: the one rule prtshade (the Gaunt table of
// prtshade/glossy.h) and libbake (the exact per-cell integrals of bake/integrators/filter.h) integrate
// polynomials with. docs/ARCHITECTURE.md §2 ("Layers": the runtime is the bottom layer).
//
// gauss_legendre(n, a, b, x, w): the n-point rule on [a, b], exact for polynomials of degree
// ≤ 2n − 1: nodes x[i] = (a + b)/2 − (b − a)/2 · z_i with z_i the roots of P_n in decreasing order
// (so x increases from a to b), found by Newton's method on P_n (three-term recurrence) from the
// guess cos(π(i + ¾)/(n + ½)), to |step| < 1e-16; weights (b − a) / ((1 − z²) P_n'(z)²).
// n >= 1; throws std::invalid_argument otherwise. Thread-safe.
#pragma once

#include <vector>

namespace prt::shade {

void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w);

} // namespace prt::shade
