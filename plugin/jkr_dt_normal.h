/* jkr/dt: the normal (JKR) interaction of Wada et al. (2007), section 2.1,
   with the viscoelastic damping of Arakawa et al. as written in eq. (A.5)
   of the 3D BPCA collision paper.

   Stateless kernels: plain numbers in, plain numbers out. No LAMMPS types,
   so the equations can be read, and tested, on their own.

   Notation (Wada et al. 2007):
     R        reduced radius,            1/R = 1/r1 + 1/r2              eq. (2)
     E*       reduced Young's modulus,   1/E* = (1-nu1^2)/E1 + (...)2   eq. (2)
     a0       equilibrium contact radius (9 pi gamma R^2 / E*)^(1/3)    eq. (1)
     delta0   equilibrium compression    a0^2 / (3R)
     delta_c  critical stretch           (9/16)^(1/3) delta0
     F_c      pull-off force             3 pi gamma R
   The kernels work with y = sqrt(a/a0), in which eq. (4) is a quartic
   with no square roots, and x^(3/2) = y^3.                               */

#ifndef JKR_DT_NORMAL_H
#define JKR_DT_NORMAL_H

#include <algorithm>
#include <cmath>

namespace JKRDT {

/* ---------------------------------------------------------------------
   constants
------------------------------------------------------------------------ */

constexpr double PI = 3.14159265358979323846;

// delta_c / delta0 = (9/16)^(1/3)
inline const double DELTA_C_RATIO = std::cbrt(9.0 / 16.0);
inline double delta_c_ratio() { return DELTA_C_RATIO; }

// y = sqrt(a/a0) at the break point: a/a0 = 6^(-2/3), where d(delta)/da = 0
inline const double Y_BREAK = 1.0 / std::cbrt(6.0);
inline double y_break() { return Y_BREAK; }

// 4 * 6^(1/3): prefactor of U_n / (F_c delta_c), eq. (6)
inline const double POTENTIAL_PREFACTOR = 4.0 * std::cbrt(6.0);
inline double potential_prefactor() { return POTENTIAL_PREFACTOR; }

/* ---------------------------------------------------------------------
   scales of one contact, eqs. (1)-(2) and section 2.1
------------------------------------------------------------------------ */

struct NormalScales {
  double R;        // reduced radius
  double a0;       // equilibrium contact radius
  double delta0;   // equilibrium compression length
  double delta_c;  // critical stretch: contact breaks at delta < -delta_c
  double F_c;      // pull-off force
};

// a0_coef = (9 pi gamma / E*)^(1/3), so that a0 = a0_coef * R^(2/3), eq. (1)
inline double a0_coefficient(double gamma, double Estar)
{
  return std::cbrt(9.0 * PI * gamma / Estar);
}

inline NormalScales normal_scales(double r1, double r2, double gamma, double a0_coef)
{
  NormalScales s;
  s.R = r1 * r2 / (r1 + r2);                      // eq. (2)
  s.a0 = a0_coef * std::cbrt(s.R * s.R);          // eq. (1)
  s.delta0 = s.a0 * s.a0 / (3.0 * s.R);           // below eq. (4)
  s.delta_c = delta_c_ratio() * s.delta0;         // below eq. (5)
  s.F_c = 3.0 * PI * gamma * s.R;                 // below eq. (5)
  return s;
}

/* ---------------------------------------------------------------------
   contact radius: invert eq. (4)
   delta/delta0 = 3 (a/a0)^2 - 2 (a/a0)^(1/2)  <=>  3 y^4 - 2 y - d = 0

   For d >= d_b = -delta_c/delta0 the stable branch is the largest root,
   y >= y_break. f(y) = 3y^4 - 2y - d is convex and increasing there.

   By Newton's method (the reference, and beyond the table below): started
   from any y with f(y) >= 0 it descends monotonically onto the root. The
   start is the smallest of three points with f >= 0: the tangent at y = 1
   (f(1) = 1 - d, f'(1) = 10), y0 = 1 + (d - 1)/10, within (d - 1)^2 / 50
   of the root near equilibrium; d^(1/4) for d > 1 (f = 2d - 2 d^(1/4));
   and near the break, where the root is double (f'(y_b) = 0), the parabola
   y_b + sqrt(2 (d - d_b) / f''(y_b)), f''(y_b) = 36 y_b^2, which the
   rising curvature of f (f''' > 0) keeps at or above the root.
------------------------------------------------------------------------ */

inline double contact_sqrt_radius_newton(double d)
{
  double y = 1.0 + 0.1 * (d - 1.0);
  if (d > 1.0) y = std::fmin(y, std::sqrt(std::sqrt(d)));
  const double above_break = d + DELTA_C_RATIO;    // d - d_b
  if (above_break >= 0.0 && above_break < 1.0)
    y = std::fmin(y, Y_BREAK + std::sqrt(above_break / (18.0 * Y_BREAK * Y_BREAK)));
  for (int iter = 0; iter < 200; ++iter) {
    const double y3 = y * y * y;
    const double f = 3.0 * y3 * y - 2.0 * y - d;
    const double fprime = 12.0 * y3 - 2.0;
    if (fprime <= 0.0) break;
    const double step = f / fprime;
    y -= step;
    if (step <= 1.0e-15 * y) break;    // monotone descent: a non-positive step is the end
  }
  return (y < Y_BREAK) ? Y_BREAK : y;
}

/* The step's solver. In t = sqrt(d - d_b) the root y(t) is smooth through
   the break (where it goes as y_b + t sqrt(2 / f''(y_b))) and out to large
   d (as (t^2/3)^(1/4)). A table of y and dy/dt = 2t / f'(y) at 256 steps
   over t in [0, 8] (d up to 63), read by cubic Hermite interpolation, is
   within 3e-9 of the root; one Newton step then squares that error (times
   f''/2f' ~ 2). One division, where Newton from a bound takes 3 to 6, and
   up to 19 near the break; tests/kernel holds it to the reference.       */
struct SqrtRadiusTable {
  static constexpr int STEPS = 256;
  static constexpr double T_MAX = 8.0;
  double inv_h;
  double node[STEPS + 1][2];    // y and h dy/dt at t = k h
};

inline SqrtRadiusTable sqrt_radius_table()
{
  SqrtRadiusTable tab{};
  const double h = SqrtRadiusTable::T_MAX / SqrtRadiusTable::STEPS;
  tab.inv_h = 1.0 / h;
  for (int k = 0; k <= SqrtRadiusTable::STEPS; ++k) {
    const double t = k * h;
    const double y = k ? contact_sqrt_radius_newton(t * t - DELTA_C_RATIO) : Y_BREAK;
    const double slope = k ? 2.0 * t / (12.0 * y * y * y - 2.0)
                           : std::sqrt(1.0 / (18.0 * Y_BREAK * Y_BREAK));
    tab.node[k][0] = y;
    tab.node[k][1] = h * slope;
  }
  return tab;
}

inline const SqrtRadiusTable SQRT_RADIUS_TABLE = sqrt_radius_table();

/* Near rest the root is a power series. With y = 1 + u and d = 1 + e, eq. (4)
   reads 10 u + 18 u^2 + 12 u^3 + 3 u^4 = e; reverted,
     u = e/10 - 9 e^2/500 + 33 e^3/6250 - 933 e^4/500000 + 45549 e^5/62500000
         - 946953 e^6/3125000000 + 20551437 e^7/156250000000
         - 1840903119 e^8/31250000000000 + ...
   whose terms fall by about 0.42 each (it converges for |e| < 2.4). To
   eighth order it is within 5.4e-17 of the root (half an ulp of y) for
   |e| < 0.05, as tests/kernel checks; evaluated in Estrin's order it has no
   division and a short dependency chain, where the table needs a square
   root and a Newton division. An aggregate's contacts sit in this range
   before they are hit and after they settle.                              */
constexpr double SERIES_E_MAX = 0.05;

inline double contact_sqrt_radius_series(double e)
{
  constexpr double c1 = 1.0 / 10.0, c2 = -9.0 / 500.0, c3 = 33.0 / 6250.0,
                   c4 = -933.0 / 500000.0, c5 = 45549.0 / 62500000.0,
                   c6 = -946953.0 / 3125000000.0, c7 = 20551437.0 / 156250000000.0,
                   c8 = -1840903119.0 / 31250000000000.0;
  const double e2 = e * e, e4 = e2 * e2;
  const double low = (c1 + c2 * e) + e2 * (c3 + c4 * e);
  const double high = (c5 + c6 * e) + e2 * (c7 + c8 * e);
  return 1.0 + e * (low + e4 * high);
}

inline double contact_sqrt_radius(double d)
{
  const double e = d - 1.0;
  if (std::fabs(e) < SERIES_E_MAX) return contact_sqrt_radius_series(e);
  constexpr double T2_MAX = SqrtRadiusTable::T_MAX * SqrtRadiusTable::T_MAX;
  const double t2 = d + DELTA_C_RATIO;    // d - d_b
  if (!(t2 < T2_MAX)) return contact_sqrt_radius_newton(d);
  if (t2 <= 0.0) return Y_BREAK;
  const double s = std::sqrt(t2) * SQRT_RADIUS_TABLE.inv_h;
  const int k = std::min(static_cast<int>(s), SqrtRadiusTable::STEPS - 1);
  const double u = s - k;
  const double *n0 = SQRT_RADIUS_TABLE.node[k], *n1 = SQRT_RADIUS_TABLE.node[k + 1];
  // cubic Hermite between nodes k and k + 1
  const double u2 = u * u, u3 = u2 * u;
  double y = (2.0 * u3 - 3.0 * u2 + 1.0) * n0[0] + (u3 - 2.0 * u2 + u) * n0[1] +
      (3.0 * u2 - 2.0 * u3) * n1[0] + (u3 - u2) * n1[1];
  // one Newton step on eq. (4)
  const double y3 = y * y * y;
  const double fprime = 12.0 * y3 - 2.0;
  if (fprime > 0.0) y -= (3.0 * y3 * y - 2.0 * y - d) / fprime;
  return (y < Y_BREAK) ? Y_BREAK : y;
}

/* ---------------------------------------------------------------------
   force and potential along the normal
------------------------------------------------------------------------ */

// F / F_c = 4 [ (a/a0)^3 - (a/a0)^(3/2) ] = 4 y^3 (y^3 - 1), eq. (5); > 0 is repulsive
inline double normal_force_ratio(double y)
{
  const double y3 = y * y * y;
  return 4.0 * y3 * (y3 - 1.0);
}

// U_n / (F_c delta_c) = 4 6^(1/3) [ 4/5 x^5 - 4/3 x^(7/2) + 1/3 x^2 ], x = y^2, eq. (6)
inline double normal_potential_ratio(double y)
{
  const double y2 = y * y;
  const double y4 = y2 * y2;
  const double y3 = y2 * y;
  return potential_prefactor() * y4 * (0.8 * y4 * y2 - (4.0 / 3.0) * y3 + 1.0 / 3.0);
}

// U_n at delta = 0, the jump at contact formation (~ -0.847 F_c delta_c)
inline double potential_ratio_at_touch()
{
  return normal_potential_ratio(contact_sqrt_radius(0.0));
}

// U_n at delta = -delta_c, the jump at separation (~ 0.089 F_c delta_c)
inline double potential_ratio_at_break() { return normal_potential_ratio(y_break()); }

/* ---------------------------------------------------------------------
   energy lost when a contact forms or breaks (section 2.1)

   U_n jumps at contact (from 0 to U_n(0) ~ -0.847 F_c delta_c) and at
   separation (from U_n(-delta_c) ~ 0.089 F_c delta_c to 0). A time step
   meets the event late, between two steps: the potential jumps from
   u_before to u_after there, and the force f on either side of the jump
   enters (formation) or leaves (breaking) the velocity-Verlet update one
   half-kick early, which moves dt/2 f v_n into the kinetic energy. The loss
   booked is both, so that ke + pe + dissipated stays continuous across the
   event; it differs from the continuum jump by O(F_c v_n dt).
   v_n is the normal relative velocity, > 0 when separating; f > 0 repulsive.
------------------------------------------------------------------------ */

inline double event_loss(double u_before, double u_after, double f, double vn, double dt)
{
  return u_before - u_after - 0.5 * dt * f * vn;
}

/* ---------------------------------------------------------------------
   viscoelastic damping, eq. (A.5): F_D = 2 T_vis E* / nu^2 * a * v_rel
   damping_coefficient() returns 2 T_vis E* / nu^2; multiply by a v_rel.
------------------------------------------------------------------------ */

inline double damping_coefficient(double tvis, double Estar, double nu)
{
  return 2.0 * tvis * Estar / (nu * nu);
}

}    // namespace JKRDT

#endif
