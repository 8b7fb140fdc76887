/* jkr/dt: the tangential interactions of Wada et al. (2007), section 2.2:
   sliding, rolling and twisting, described by the contact pointers n1, n2
   and the twisting angle phi, with the clamped inelasticity of section 2.2.5.

   Stateless kernels, as in jkr_dt_normal.h: plain numbers in, plain numbers
   out. Particle 1 is the atom with the smaller ID; n_c points from particle
   2 to particle 1, eq. (9).

   Notation (Wada et al. 2007):
     zeta     sliding displacement                 eqs. (8)-(10)
     xi       rolling displacement  R (n1 + n2)    eq. (20)
     phi      twisting angle                       eq. (24)
     k_s      8 a0 G*                              eqs. (12)-(13)
     k_r      4 F_c / R = 12 pi gamma              eq. (22)
     k_t      16/3 G a0^3, G the reduced shear modulus (1/G1 + 1/G2)^-1, eq. (26)
     zeta_crit = F_fric / k_s, F_fric = G a0^2 / (2 pi), eqs. (35)-(36)
     phi_crit  = M_fric / k_t = 1 / (16 pi),             eqs. (37)-(38)       */

#ifndef JKR_DT_TANGENTIAL_H
#define JKR_DT_TANGENTIAL_H

#include "jkr_dt_normal.h"

#include <cmath>

namespace JKRDT {

/* ---------------------------------------------------------------------
   three-vectors
------------------------------------------------------------------------ */

// one 3-vector, or (T a vector of doubles) the same 3-vector of several contacts, one per
// lane: the functions below that take V3T<T> do the same arithmetic in every lane, so a
// lane's result has the bits of the same function called on that contact alone
template <class T> struct V3T {
  T x, y, z;
};
using V3 = V3T<double>;

inline V3 vec(const double *a) { return {a[0], a[1], a[2]}; }
inline void store(const V3 &a, double *out) { out[0] = a.x; out[1] = a.y; out[2] = a.z; }
template <class T> inline V3T<T> operator+(const V3T<T> &a, const V3T<T> &b)
{
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T> inline V3T<T> operator-(const V3T<T> &a, const V3T<T> &b)
{
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T> inline V3T<T> operator-(const V3T<T> &a) { return {-a.x, -a.y, -a.z}; }
template <class S, class T> inline V3T<T> operator*(const S &s, const V3T<T> &a)
{
  return {s * a.x, s * a.y, s * a.z};
}
template <class T> inline T dot(const V3T<T> &a, const V3T<T> &b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double norm(const V3 &a) { return std::sqrt(dot(a, a)); }
template <class T> inline V3T<T> cross(const V3T<T> &a, const V3T<T> &b)
{
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline V3 unit(const V3 &a) { return (1.0 / norm(a)) * a; }

// lanes of two (any x86-64: SSE2) and of four doubles (AVX2, or two SSE2 halves)
typedef double Lanes __attribute__((vector_size(16)));
typedef double Lanes4 __attribute__((vector_size(32)));

/* ---------------------------------------------------------------------
   tracing of the contact pointers, section 2.2.4

   A pointer is fixed in its particle, so it turns with the particle's
   rotation. Over one step the particle turns by omega dt, with omega its
   angular velocity at the half step (the value velocity Verlet drifts
   with): the rotation by the angle |omega| dt about omega (Rodrigues).
   This is eqs. (32)-(33) integrated exactly over the step with omega held
   at its half-step value: the rotational twin of x += v dt. It keeps the
   scheme time-reversible and second order. Turning the pointers directly
   needs no per-particle orientation, which atom_style sphere does not
   have; it is the same as eqs. (28)-(29) with n' fixed in the particle.
------------------------------------------------------------------------ */

// n turned by the angle vector w = omega dt:  n + a (w x n) + b w x (w x n),
// a = sin(t)/t, b = (1 - cos t)/t^2, t = |w| (Rodrigues), with w x (w x n) =
// w (w . n) - t^2 n. Below t = 0.01 the series to t^6 is exact in double
// precision and needs no sqrt, sin or cos (its coefficients are multiplied, not
// divided: a division costs more than the rest of the turn). One Newton step for
// 1/|n| puts the result back on the unit sphere.
// the series of a and b, below t^2 = 1e-4; T: a number, or one per lane
template <class T> inline T turn_series_a(const T &t2)
{
  return 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * (1.0 / 20.0) * (1.0 - t2 * (1.0 / 42.0)));
}
template <class T> inline T turn_series_b(const T &t2)
{
  return 0.5 - t2 * (1.0 / 24.0) * (1.0 - t2 * (1.0 / 30.0) * (1.0 - t2 * (1.0 / 56.0)));
}

// n + a (w x n) + b w (w . n) - b t^2 n, renormalized: the rotation of n by w, given a, b
template <class T>
inline V3T<T> rodrigues(const V3T<T> &n, const V3T<T> &w, const T &t2, const T &a, const T &b)
{
  const V3T<T> r = (1.0 - b * t2) * n + a * cross(w, n) + (b * dot(w, n)) * w;
  return (1.5 - 0.5 * dot(r, r)) * r;
}

// the turn by the series: for |w|^2 < TURN_SERIES_T2 in every lane
constexpr double TURN_SERIES_T2 = 1.0e-4;
template <class T> inline V3T<T> turned_series(const V3T<T> &n, const V3T<T> &w, const T &t2)
{
  return rodrigues(n, w, t2, turn_series_a(t2), turn_series_b(t2));
}

inline V3 turned(const V3 &n, const V3 &w)
{
  const double t2 = dot(w, w);
  if (t2 < TURN_SERIES_T2) return turned_series(n, w, t2);
  const double t = std::sqrt(t2);
  return rodrigues(n, w, t2, std::sin(t) / t, (1.0 - std::cos(t)) / t2);
}

// the two pointers of a contact turned at once, n1 by w1 and n2 by w2, one lane per
// particle, so the result equals two calls of turned() bit for bit
using V3x2 = V3T<Lanes>;
inline V3x2 lanes(const V3 &a, const V3 &b) { return {Lanes{a.x, b.x}, Lanes{a.y, b.y}, Lanes{a.z, b.z}}; }
inline V3 lane(const V3x2 &p, int k) { return {p.x[k], p.y[k], p.z[k]}; }

inline void turned(V3 &n1, const V3 &w1, V3 &n2, const V3 &w2)
{
  const V3x2 n = lanes(n1, n2), w = lanes(w1, w2);
  const Lanes t2 = dot(w, w);
  if (!(t2[0] < TURN_SERIES_T2 && t2[1] < TURN_SERIES_T2)) {
    n1 = turned(n1, w1);
    n2 = turned(n2, w2);
    return;
  }
  const V3x2 out = turned_series(n, w, t2);
  n1 = lane(out, 0);
  n2 = lane(out, 1);
}

/* ---------------------------------------------------------------------
   stiffnesses and elastic limits of one contact
------------------------------------------------------------------------ */

struct Tangential {
  bool sliding, rolling, twisting;
  double k_s, zeta_crit;    // eqs. (12), (36)
  double k_r, xi_crit;      // eq. (22); xi_crit is a parameter
  double k_t, phi_crit;     // eqs. (26), (38)
};

// phi_crit = M_t,fric / k_t, eqs. (37)-(38): 1/(16 pi), about 1.1 degrees
constexpr double PHI_CRIT = 1.0 / (16.0 * PI);
inline double phi_crit() { return PHI_CRIT; }

// a channel beyond its elastic limit (|zeta| > zeta_crit, eq. 36; |xi| > xi_crit;
// |phi| > phi_crit, eq. 38), where section 2.2.5's clamp acts; for one contact (T = double)
// and for a lane of four (T = Lanes4, a mask per lane). A NaN is never beyond: it goes on
// to the force, where the pair loop names it
template <class T> inline auto sliding_beyond(const Tangential &K, const T &zeta2)
{
  return zeta2 > K.zeta_crit * K.zeta_crit;
}
template <class T> inline auto rolling_beyond(const Tangential &K, const T &xi2)
{
  return xi2 > K.xi_crit * K.xi_crit;
}
template <class T> inline auto twisting_beyond(const Tangential &K, const T &phi)
{
  return (phi > K.phi_crit) | (phi < -K.phi_crit);
}

/* ---------------------------------------------------------------------
   displacements, eqs. (8)-(10) and (20)
------------------------------------------------------------------------ */

template <class T> struct ContactStateT {
  V3T<T> n1, n2;    // contact pointers
  T phi;            // twisting angle along n_c, eq. (24)
};
using ContactState = ContactStateT<double>;

// zeta_0, eq. (8)
template <class T>
inline V3T<T> sliding_zeta0(const ContactStateT<T> &c, const V3T<T> &nc, double r1, double r2)
{
  return r1 * c.n1 - r2 * c.n2 + (r1 + r2) * nc;
}

// zeta, the part of zeta_0 normal to n_c, eq. (10)
template <class T> inline V3T<T> tangential_part(const V3T<T> &a, const V3T<T> &nc)
{
  return a - dot(a, nc) * nc;
}

// xi = R (n1 + n2), eq. (20)
template <class T> inline V3T<T> rolling_xi(const ContactStateT<T> &c, double R)
{
  return R * (c.n1 + c.n2);
}

// the displacements a state's loads and limits are made of, computed once per step
template <class T> struct DisplacementsT {
  V3T<T> zeta0;    // eq. (8)
  V3T<T> zeta;     // eq. (10)
  V3T<T> xi;       // eq. (20)
};
using Displacements = DisplacementsT<double>;

template <class T>
inline DisplacementsT<T> displacements(const ContactStateT<T> &c, const V3T<T> &nc, double r1,
                                       double r2, double R)
{
  DisplacementsT<T> d;
  d.zeta0 = sliding_zeta0(c, nc, r1, r2);
  d.zeta = tangential_part(d.zeta0, nc);
  d.xi = rolling_xi(c, R);
  return d;
}

/* ---------------------------------------------------------------------
   potentials, forces and torques of each channel, eqs. (11)-(27)
------------------------------------------------------------------------ */

// the tangential channels of section 2.2, declared once: X(enum, name, potential). Every
// list of channels is made from this one and JKRDT_NORMAL_CHANNELS (jkr_dt_contact.h): the
// ledger's columns, compute pair jkr/dt's values and their names, which Python's
// jkrdt.ledger gives too (tests/test_kernel.py compares them)
#define JKRDT_TANGENTIAL_CHANNELS(X) X(SLIDE, "sliding", "U_s") X(ROLL, "rolling", "U_r") \
  X(TWIST, "twisting", "U_t")
#define JKRDT_CHANNEL_ENUM(e, name, potential) e,
enum Channel { JKRDT_TANGENTIAL_CHANNELS(JKRDT_CHANNEL_ENUM) NCHANNEL };
#undef JKRDT_CHANNEL_ENUM

struct ChannelLoad {
  double U;    // potential, eqs. (11), (21), (25)
  V3 F1;       // force on particle 1 (particle 2 gets -F1), eq. (14)
  V3 M1, M2;   // torques on particles 1 and 2, eqs. (17), (23), (27)
};

// each channel's load on its own. nc = (x1 - x2) rinv, rinv = 1 / |x1 - x2|, eq. (9);
// d the state's displacements (of the channels that are on)
inline void tangential_load(const ContactState &c, const Displacements &d, const V3 &nc,
                            double rinv, double r1, double r2, double R, const Tangential &K,
                            ChannelLoad load[NCHANNEL])
{
  const V3 zero = {0.0, 0.0, 0.0};
  if (!(K.sliding && K.rolling && K.twisting))
    for (int ch = 0; ch < NCHANNEL; ch++) load[ch] = {0.0, zero, zero, zero};

  if (K.sliding) {
    const V3 &zeta0 = d.zeta0;
    const V3 &zeta = d.zeta;
    ChannelLoad &s = load[SLIDE];
    s.U = 0.5 * K.k_s * dot(zeta, zeta);                                 // eq. (11)
    s.F1 = (-K.k_s * (r1 + r2 - dot(zeta0, nc)) * rinv) * zeta;         // eq. (14)
    s.M1 = (-r1 * K.k_s) * cross(c.n1, zeta);                            // eq. (17)
    s.M2 = (r2 * K.k_s) * cross(c.n2, zeta);                             // (17), 1 <-> 2, zeta -> -zeta
  }
  if (K.rolling) {
    const V3 &xi = d.xi;
    ChannelLoad &r = load[ROLL];
    r.U = 0.5 * K.k_r * dot(xi, xi);                                     // eq. (21)
    r.F1 = zero;
    r.M1 = (-R * K.k_r) * cross(c.n1, xi);                               // eq. (23)
    r.M2 = (-R * K.k_r) * cross(c.n2, xi);
  }
  if (K.twisting) {
    ChannelLoad &t = load[TWIST];
    t.U = 0.5 * K.k_t * c.phi * c.phi;                                   // eq. (25)
    t.F1 = zero;
    t.M1 = (-K.k_t * c.phi) * nc;                                        // eq. (27)
    t.M2 = -t.M1;
  }
}

inline void tangential_load(const ContactState &c, const V3 &nc, double rinv, double r1, double r2,
                            double R, const Tangential &K, ChannelLoad load[NCHANNEL])
{
  tangential_load(c, displacements(c, nc, r1, r2, R), nc, rinv, r1, r2, R, K, load);
}

// the channels' loads summed, as a step that books nothing needs them: the same
// eqs. (14)-(27); every torque of eqs. (17) and (23) is its pointer crossed with a
// displacement, so each particle's takes one cross product:
//   M1 = n1 x (-r1 k_s zeta - R k_r xi) - k_t phi n_c
//   M2 = n2 x ( r2 k_s zeta - R k_r xi) + k_t phi n_c
// adds to F1, M1, M2; the potentials go to U only if energy is asked for
template <class T>
inline void add_tangential_loads(const ContactStateT<T> &c, const DisplacementsT<T> &d,
                                 const V3T<T> &nc, const T &rinv, double r1, double r2,
                                 double R, const Tangential &K, bool energy, V3T<T> &F1,
                                 V3T<T> &M1, V3T<T> &M2, T U[NCHANNEL])
{
  V3T<T> arm1 = {T{}, T{}, T{}}, arm2 = arm1;
  if (K.sliding) {
    F1 = F1 + (-K.k_s * (r1 + r2 - dot(d.zeta0, nc)) * rinv) * d.zeta;   // eq. (14)
    arm1 = (-r1 * K.k_s) * d.zeta;                                       // eq. (17)
    arm2 = (r2 * K.k_s) * d.zeta;
    if (energy) U[SLIDE] = 0.5 * K.k_s * dot(d.zeta, d.zeta);             // eq. (11)
  }
  if (K.rolling) {
    const double k = -R * K.k_r;                                         // eq. (23)
    arm1 = arm1 + k * d.xi;
    arm2 = arm2 + k * d.xi;
    if (energy) U[ROLL] = 0.5 * K.k_r * dot(d.xi, d.xi);                  // eq. (21)
  }
  if (K.sliding || K.rolling) {
    M1 = M1 + cross(c.n1, arm1);
    M2 = M2 + cross(c.n2, arm2);
  }
  if (K.twisting) {
    const V3T<T> twist = (-K.k_t * c.phi) * nc;                          // eq. (27)
    M1 = M1 + twist;
    M2 = M2 - twist;
    if (energy) U[TWIST] = 0.5 * K.k_t * c.phi * c.phi;                   // eq. (25)
  }
}

// work done on the particles by a channel's load over a step in which
// particle 1 moves by dx1 and turns by dtheta1 (and likewise particle 2)
inline double channel_work(const ChannelLoad &l, const V3 &dx12, const V3 &dtheta1,
                           const V3 &dtheta2)
{
  return dot(l.F1, dx12) + dot(l.M1, dtheta1) + dot(l.M2, dtheta2);
}

/* ---------------------------------------------------------------------
   inelastic regimes, section 2.2.5

   A displacement beyond its elastic limit is brought back to the limit, so
   that the force or torque stays at its critical value (Fig. 3). The
   pointers are moved by eq. (42), with the factor alpha of eq. (A8) that
   makes up for what renormalization takes off the shift.

   Eq. (42) writes the sliding shifts of n1 and n2 with the same sign; with
   zeta_0 = r1 n1 - r2 n2 + ..., n2 must move the other way, or the two
   shifts cancel in zeta. For unequal radii the shifts are chosen so that
   each correction leaves the other displacement unchanged:
     sliding   n1 -= dzeta / (r1 + r2),   n2 += dzeta / (r1 + r2)   (xi unchanged)
     rolling   n1 -= dxi / r1,            n2 -= dxi / r2            (zeta unchanged)
   For r1 = r2 = r these are dzeta / 2r and dxi / 2R, as in eq. (42).
------------------------------------------------------------------------ */

// n - alpha shift, renormalized; alpha = 1 + 1/tan^2(theta1), eq. (A8), with
// cos(theta1) the cosine between n and the shift, eq. (A5)
inline V3 corrected_pointer(const V3 &n, const V3 &shift)
{
  const double l = norm(shift);
  if (l == 0.0) return n;
  const double cos1 = dot(n, shift) / l;
  // a pointer lies within ~zeta_crit / r of the contact normal, nearly
  // normal to the shift (alpha ~ 1); the bound only guards absurd states
  const double sin2 = std::fmax(1.0 - cos1 * cos1, 0.5);
  return unit(n - (1.0 / sin2) * shift);
}

// bring the displacements back to their elastic limits; returns a bit per
// channel that was clamped, and the displacements of the state it leaves in d
[[gnu::always_inline]] inline int clamp_to_elastic_limits(ContactState &c, const V3 &nc,
                                                          double r1, double r2, double R,
                                                          const Tangential &K, Displacements &d)
{
  int clamped = 0;
  if (K.sliding) {
    d.zeta0 = sliding_zeta0(c, nc, r1, r2);
    d.zeta = tangential_part(d.zeta0, nc);
    const V3 &zeta = d.zeta;
    const double z2 = dot(zeta, zeta);
    if (sliding_beyond(K, z2)) {
      const double z = std::sqrt(z2);
      const V3 shift = ((1.0 - K.zeta_crit / z) / (r1 + r2)) * zeta;    // dzeta / (r1 + r2)
      c.n1 = corrected_pointer(c.n1, shift);                            // eq. (42)
      c.n2 = corrected_pointer(c.n2, -shift);
      clamped |= 1 << SLIDE;
    }
  }
  if (K.rolling) {
    d.xi = rolling_xi(c, R);
    const V3 &xi = d.xi;
    const double x2 = dot(xi, xi);
    if (rolling_beyond(K, x2)) {
      const double x = std::sqrt(x2);
      const V3 dxi = (1.0 - K.xi_crit / x) * xi;
      c.n1 = corrected_pointer(c.n1, (1.0 / r1) * dxi);                 // eq. (42) for rolling
      c.n2 = corrected_pointer(c.n2, (1.0 / r2) * dxi);
      clamped |= 1 << ROLL;
    }
  }
  if (K.twisting && twisting_beyond(K, c.phi)) {
    c.phi = std::copysign(K.phi_crit, c.phi);
    clamped |= 1 << TWIST;
  }
  if (clamped & ((1 << SLIDE) | (1 << ROLL))) d = displacements(c, nc, r1, r2, R);    // moved
  return clamped;
}

/* ---------------------------------------------------------------------
   energy dissipated in a step, eqs. (39)-(41) made exact for the scheme

   Velocity Verlet changes the kinetic energy over a step by the trapezoid
   of the work of the loads at its two ends (plus a term that telescopes).
   The dissipation of a channel is what that work and the change of the
   channel's potential leave over:
     dE_dis = - (W_before + W_after) / 2 - (U_after - U_before)
   For a clamp on the plateau this is k zeta_crit (|zeta| - zeta_crit),
   eq. (39); on entering the plateau, and for the coupling between the
   channels through the shared pointers, it is exact where eq. (39) is first
   order. When the contact breaks, the load after is zero and the spring's
   energy is lost: dE_dis = U_before - W_before / 2.
------------------------------------------------------------------------ */

inline double step_dissipation(double u_before, double w_before, double u_after, double w_after)
{
  return -0.5 * (w_before + w_after) - (u_after - u_before);
}

}    // namespace JKRDT

#endif
