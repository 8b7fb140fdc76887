// Unit tests of the per-contact kernel (plugin/jkr_dt_contact.h), without LAMMPS.
// Built and run by tests/test_kernel.py (or CTest: cmake -DJKRDT_KERNEL_TESTS=ON).
// Each check prints one line; the exit status is the number of failed checks.
//
// Material: ice of Wada et al. (2007), Table 2; two grains of r = 0.1 micron.

#include "jkr_dt_contact.h"
#include "jkr_dt_lanes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

using namespace JKRDT;

static int failures = 0;

static void check(bool ok, const char *what, double got, double want, double tol)
{
  std::printf("%s %s: got %.17g want %.17g (tol %.3g)\n", ok ? "ok  " : "FAIL", what, got, want,
              tol);
  if (!ok) failures++;
}

static void close(const char *what, double got, double want, double tol)
{
  check(std::fabs(got - want) <= tol, what, got, want, tol);
}

constexpr double R_GRAIN = 1.0e-7, GAMMA = 0.1, E = 7.0e9, NU = 0.25, DENSITY = 1000.0;
constexpr double XI_CRIT = 8.0e-10;

static Coefficients ice(bool sliding, bool rolling, bool twisting, double tvis = 0.0)
{
  const double G = E / (2.0 * (1.0 + NU));
  const double Estar = 1.0 / (2.0 * (1.0 - NU * NU) / E);     // eq. (2)
  const double Gstar = 1.0 / (2.0 * (2.0 - NU) / G);          // eq. (13)
  const double Gred = 0.5 * G;
  Coefficients P;
  P.gamma = GAMMA;
  P.a0_coef = a0_coefficient(GAMMA, Estar);
  P.damp_coef = tvis > 0.0 ? damping_coefficient(tvis, Estar, NU) : 0.0;
  P.xi_crit = XI_CRIT;
  P.ks_coef = 8.0 * Gstar;
  P.zeta_coef = Gred / (16.0 * PI * Gstar);
  P.k_r = 12.0 * PI * GAMMA;
  P.kt_coef = 16.0 / 3.0 * Gred;
  P.sliding = sliding;
  P.rolling = rolling;
  P.twisting = twisting;
  return P;
}

static const StateLayout FULL = {-1, 0, 6, 7};    // pointers, then phi

// two grains on the x axis at compression delta, at rest
static ContactMotion at_rest(double delta)
{
  ContactMotion m;
  m.r = 2.0 * R_GRAIN - delta;
  m.rinv = 1.0 / m.r;
  m.d12 = {m.r, 0.0, 0.0};
  m.v12 = m.w1 = m.w2 = {0.0, 0.0, 0.0};
  m.vn = 0.0;
  return m;
}

// eq. (5) against eq. (4): at a/a0 = x the compression is delta0 (3 x^2 - 2 x^(1/2)) and
// the force 4 F_c (x^3 - x^(3/2)); from the break point to twice the equilibrium radius
static void force_against_eq5()
{
  const ContactConstants c = contact_constants(ice(false, false, false), R_GRAIN, R_GRAIN);
  const StateLayout none;
  for (double x : {0.31, 0.5, 0.8, 1.0, 1.3, 2.0}) {
    const double delta = c.S.delta0 * (3.0 * x * x - 2.0 * std::sqrt(x));
    ContactResult out;
    contact_step(c, none, at_rest(delta), delta, 1e-12, true, false, true, nullptr, out);
    const double want = 4.0 * c.S.F_c * (x * x * x - std::pow(x, 1.5));
    char what[64];
    std::snprintf(what, sizeof what, "eq. (5) force at a/a0 = %.2f", x);
    close(what, out.F1.x, want, 1e-12 * c.S.F_c);
  }
}

// eq. (4) inverted: the step's solver (a table and one Newton step) against Newton's method
// run to convergence from a bound, over d = delta/delta0 from the break point (d_b) to 100,
// beyond the table's end at 63 too. Relative to y: within 1e-14 one hundredth past the break;
// within 1e-11 right at it, where the root is double and y moves as sqrt(d - d_b), so that
// d's own round-off moves y by 1e-8 (the force by 3e-8 F_c, measured 5e-13 F_c at most)
static void sqrt_radius_solver()
{
  const double db = -delta_c_ratio();
  double near = 0.0, far = 0.0, force = 0.0, residual = 0.0;
  for (int k = 0; k <= 400000; ++k) {
    const double t = 10.1 * k / 400000.0;    // t = sqrt(d - d_b): dense at the break
    const double d = db + t * t;
    const double y = contact_sqrt_radius(d), ref = contact_sqrt_radius_newton(d);
    const double rel = std::fabs(y - ref) / ref;
    (t * t < 0.01 ? near : far) = std::max(t * t < 0.01 ? near : far, rel);
    force = std::max(force, std::fabs(normal_force_ratio(y) - normal_force_ratio(ref)));
    if (t * t >= 0.01)
      residual = std::max(residual, std::fabs(3.0 * y * y * y * y - 2.0 * y - d) / (1.0 + d));
  }
  close("eq. (4) solver against Newton, relative, d - d_b >= 0.01", far, 0.0, 1e-14);
  close("eq. (4) solver against Newton, relative, at the break", near, 0.0, 1e-11);
  close("eq. (4) solver: force against Newton's, in F_c", force, 0.0, 1e-11);
  // (the residual's own evaluation rounds each of its terms: ~10 ulp of 1 + d)
  close("eq. (4) solver: residual |3y^4 - 2y - d| / (1 + d)", residual, 0.0, 2e-15);
  close("eq. (4) solver at equilibrium (d = 1)", contact_sqrt_radius(1.0), 1.0, 2e-16);
  // near rest (|d - 1| < SERIES_E_MAX) the step takes the reverted series: its truncation
  // is 5.4e-17 at the range's ends, its evaluation rounds a few terms of size <= 0.005;
  // within 2 ulp of y ~ 1 of the converged Newton root everywhere in the range
  double series = 0.0;
  for (int k = -100000; k <= 100000; ++k) {
    const double d = 1.0 + SERIES_E_MAX * k / 100000.0 * (1.0 - 1e-12);
    series = std::max(series, std::fabs(contact_sqrt_radius(d) - contact_sqrt_radius_newton(d)));
  }
  close("eq. (4) near rest: series against Newton, |d - 1| < 0.05", series, 0.0, 4.5e-16);
  close("eq. (4) solver at the break (d = d_b)", contact_sqrt_radius(db), y_break(), 0.0);
}

// eqs. (36)-(38): a displacement beyond its limit is brought back to the limit, so the
// force or torque sits at its critical value, and what the clamp dissipates is what the
// spring lost. The pointer correction of eqs. (42), (A8) is exact to second order in the
// overshoot: a step's overshoot of 1 % leaves |zeta| and |xi| within 1e-7 of the limit
// (measured: 7e-10 and 1e-8; at 10 %: 7e-8 and 1e-6)
static void clamps()
{
  const ContactConstants c = contact_constants(ice(true, true, true), R_GRAIN, R_GRAIN);
  const double delta = c.S.delta0;
  const ContactMotion m = at_rest(delta);
  const V3 nc = {1.0, 0.0, 0.0};

  // sliding: the pointers tilted opposite ways by t: zeta = (r1 + r2) t = 1.01 zeta_crit
  {
    const double t = 1.01 * c.K.zeta_crit / (2.0 * R_GRAIN), norm1 = std::sqrt(1.0 + t * t);
    double s[7] = {-1.0 / norm1, t / norm1, 0.0, 1.0 / norm1, -t / norm1, 0.0, 0.0};
    ContactState before;
    load_state(s, FULL, before);
    const double zeta_before = norm(tangential_part(sliding_zeta0(before, nc, R_GRAIN, R_GRAIN), nc));
    ContactResult out;
    contact_step(c, FULL, m, delta, 1e-12, false, false, true, s, out);
    ContactState after;
    load_state(s, FULL, after);
    const double zeta = norm(tangential_part(sliding_zeta0(after, nc, R_GRAIN, R_GRAIN), nc));
    close("eq. (36): |zeta| clamped to zeta_crit", zeta, c.K.zeta_crit, 1e-7 * c.K.zeta_crit);
    // eq. (14) at the limit: F_fric = k_s zeta_crit (eq. 35) times (r1 + r2) / |x1 - x2|
    const double F = c.K.k_s * c.K.zeta_crit * 2.0 * R_GRAIN / m.r;
    close("eqs. (14), (35): sliding force at F_fric", std::hypot(out.F1.y, out.F1.z), F, 1e-5 * F);
    // nothing moved in the step: what the clamp dissipated is what the spring lost
    const double lost = 0.5 * c.K.k_s * (zeta_before * zeta_before - zeta * zeta);
    close("sliding loss of the clamp = drop of U_s", out.loss[LOSS_SLIDE], lost, 1e-9 * lost);
  }
  // rolling: the pointers tilted the same way by t: xi = R (n1 + n2) = 1.01 xi_crit, zeta = 0
  {
    const double R = c.S.R;
    const double t = 0.505 * XI_CRIT / R, norm1 = std::sqrt(1.0 + t * t);
    double s[7] = {-1.0 / norm1, t / norm1, 0.0, 1.0 / norm1, t / norm1, 0.0, 0.0};
    ContactResult out;
    contact_step(c, FULL, m, delta, 1e-12, false, false, true, s, out);
    ContactState after;
    load_state(s, FULL, after);
    close("rolling: |xi| clamped to xi_crit", norm(rolling_xi(after, R)), XI_CRIT, 1e-7 * XI_CRIT);
    // eq. (23) at the limit: R k_r xi_crit = 4 F_c xi_crit, to the pointers' tilt t^2 / 2
    const double M_roll = c.K.k_r * XI_CRIT * R;
    close("eq. (23): rolling torque at 4 F_c xi_crit", norm(out.M1), M_roll, 1e-3 * M_roll);
  }
  // twisting: phi = 5 phi_crit
  {
    double s[7] = {-1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 5.0 * PHI_CRIT};
    ContactResult out;
    contact_step(c, FULL, m, delta, 1e-12, false, false, true, s, out);
    close("eq. (38): |phi| clamped to phi_crit", s[6], PHI_CRIT, 1e-15);
    const double M_fric = c.K.k_t * PHI_CRIT;    // eq. (37)
    close("eq. (37): twisting torque at M_t,fric", std::fabs(out.M1.x), M_fric, 1e-12 * M_fric);
  }
}

// a run's set-up (setup = true) evaluates the stored state and changes nothing: a contact
// the last step left on its plateaus (sliding and rolling both clamped, so the second-order
// residual of eq. (42) is there) keeps its pointers bit for bit and gets the step's loads
// again, which is what makes a run continued from a restart file the uninterrupted run
static void setup_changes_nothing()
{
  const ContactConstants c = contact_constants(ice(true, true, true), R_GRAIN, R_GRAIN);
  const double delta = c.S.delta0;
  const ContactMotion m = at_rest(delta);
  const double ts = 0.55 * c.K.zeta_crit / R_GRAIN, tr = 0.55 * XI_CRIT / c.S.R;    // 1.15x
  const double t1 = tr + ts, t2 = tr - ts;
  double s[7] = {-1.0, t1, 0.3 * t1, 1.0, t2, 0.3 * t2, 2.0 * PHI_CRIT};
  for (int k = 0; k < 3; k++) s[k] /= std::sqrt(1.0 + 1.09 * t1 * t1);
  for (int k = 3; k < 6; k++) s[k] /= std::sqrt(1.0 + 1.09 * t2 * t2);
  ContactResult step, again;
  contact_step(c, FULL, m, delta, 1e-12, false, false, true, s, step);
  check(step.loss[LOSS_SLIDE] > 0.0 && step.loss[LOSS_ROLL] > 0.0, "the step clamped "
        "sliding and rolling (their losses > 0)", step.loss[LOSS_SLIDE], 0.0, 0.0);
  double stored[7];
  std::copy(s, s + 7, stored);
  contact_step(c, FULL, m, delta, 1e-12, true, false, true, s, again);
  int moved = 0;
  for (int k = 0; k < 7; k++) moved += s[k] != stored[k];
  check(moved == 0, "set-up: stored state unchanged (values that moved)", moved, 0, 0);
  const double dF = norm(again.F1 - step.F1), dM = norm(again.M1 - step.M1);
  const double dU = std::fabs(again.U[SLIDE] + again.U[ROLL] - step.U[SLIDE] - step.U[ROLL]);
  check(dF == 0.0 && dM == 0.0 && dU == 0.0, "set-up: the step's force, torque and U again "
        "(|dF| + |dM| + |dU|)", dF + dM + dU, 0.0, 0.0);
  double lost = 0.0;
  for (double l : again.loss) lost += std::fabs(l);
  check(lost == 0.0, "set-up books nothing", lost, 0.0, 0.0);
}

// one contact conserves momentum (particle 2 gets -F1 by construction) and angular
// momentum: d12 x F1 + M1 + M2 = 0 for any pointers, all channels on, inside the limits
static void angular_momentum()
{
  const ContactConstants c = contact_constants(ice(true, true, true), R_GRAIN, R_GRAIN);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0, scale = 0.0;
  for (int trial = 0; trial < 100; trial++) {
    const double delta = c.S.delta0 * (0.5 + 0.5 * u(rng));
    ContactMotion m = at_rest(delta);
    const V3 tilt1 = {0.0, 0.4 * c.K.zeta_crit / R_GRAIN * u(rng), 0.4 * XI_CRIT / R_GRAIN * u(rng)};
    const V3 tilt2 = {0.0, 0.4 * c.K.zeta_crit / R_GRAIN * u(rng), 0.4 * XI_CRIT / R_GRAIN * u(rng)};
    const V3 n1 = unit(V3{-1.0, 0.0, 0.0} + tilt1), n2 = unit(V3{1.0, 0.0, 0.0} + tilt2);
    double s[7] = {n1.x, n1.y, n1.z, n2.x, n2.y, n2.z, 0.5 * PHI_CRIT * u(rng)};
    ContactResult out;
    contact_step(c, FULL, m, delta, 1e-12, true, false, true, s, out);
    const V3 L = cross(m.d12, out.F1) + out.M1 + out.M2;
    worst = std::fmax(worst, norm(L));
    scale = std::fmax(scale, norm(out.M1) + norm(cross(m.d12, out.F1)));
  }
  check(worst <= 1e-12 * scale, "angular momentum of one contact: |d12 x F1 + M1 + M2|", worst,
        0.0, 1e-12 * scale);
}

// a single elastic oscillation under velocity Verlet: two grains bound at equilibrium,
// kicked apart by a tenth of the speed that would part them; over 20 periods the energy
// ke + U_n swings by no more than (omega dt)^2 / 2 of the oscillation's energy: velocity
// Verlet's swing on a harmonic spring is (omega dt)^2 / 4, with omega = sqrt(k / mu) of
// the linearised contact, and the JKR spring stiffens under compression (measured: 0.25)
static void elastic_oscillation()
{
  const ContactConstants c = contact_constants(ice(false, false, false), R_GRAIN, R_GRAIN);
  const StateLayout none;
  const double mass = DENSITY * 4.0 / 3.0 * PI * R_GRAIN * R_GRAIN * R_GRAIN, mu = 0.5 * mass;
  auto force = [&](double delta, double &u) {
    ContactResult out;
    contact_step(c, none, at_rest(delta), delta, 1e-12, true, false, true, nullptr, out);
    u = out.U_n;
    return out.F1.x;    // > 0 repulsive, along the separation
  };
  double u;
  const double h = 1e-6 * c.S.delta0;
  const double k = (force(c.S.delta0 + h, u) - force(c.S.delta0 - h, u)) / (2.0 * h);
  const double omega = std::sqrt(k / mu);
  const double t_c = std::sqrt(mass * c.S.delta_c / c.S.F_c);    // eq. (49)
  const double dt = 0.01 * t_c;
  // separation s = r - (r1 + r2) = -delta; relative velocity w = ds/dt
  double delta = c.S.delta0, w = 0.1 * std::sqrt(2.0 * 1.5426 * c.S.F_c * c.S.delta_c / mu);
  double fn = force(delta, u);
  const double e0 = 0.5 * mu * w * w + u;
  double worst = 0.0;
  const int steps = static_cast<int>(20 * 2.0 * PI / omega / dt);
  for (int n = 0; n < steps; n++) {
    w += 0.5 * dt * fn / mu;
    delta -= w * dt;
    fn = force(delta, u);
    w += 0.5 * dt * fn / mu;
    worst = std::fmax(worst, std::fabs(0.5 * mu * w * w + u - e0));
  }
  const double e_osc = 0.5 * mu * std::pow(0.1, 2) * 2.0 * 1.5426 * c.S.F_c * c.S.delta_c / mu;
  const double bound = 0.5 * std::pow(omega * dt, 2) * e_osc;
  check(worst <= bound, "elastic oscillation: max |dE| within (omega dt)^2/2 E_osc", worst,
        0.0, bound);
}

// the step's fast forms against the plain ones: the two pointers turned in lanes equal two
// scalar turns bit for bit (the same operations in the same order), and the channels'
// loads summed with one cross product per particle equal the sum of each channel's load
// of eqs. (14)-(27) to round-off (a few ulps of the largest term)
static void fast_forms()
{
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_unit = [&]() { return unit(V3{u(rng), u(rng), u(rng)}); };
  int differ = 0;
  for (int k = 0; k < 1000; k++) {
    const double scale = std::pow(10.0, -4.0 * (k % 4) - 1.0);    // |w| from 0.1 to 1e-13
    const V3 w1 = scale * V3{u(rng), u(rng), u(rng)}, w2 = scale * V3{u(rng), u(rng), u(rng)};
    V3 n1 = random_unit(), n2 = random_unit();
    const V3 one = turned(n1, w1), two = turned(n2, w2);
    turned(n1, w1, n2, w2);
    differ += (n1.x != one.x) + (n1.y != one.y) + (n1.z != one.z) + (n2.x != two.x) +
        (n2.y != two.y) + (n2.z != two.z);
  }
  check(differ == 0, "pointers turned in lanes = two scalar turns (components that differ)",
        differ, 0, 0);

  const ContactConstants c = contact_constants(ice(true, true, true), R_GRAIN, R_GRAIN);
  double worst = 0.0;
  for (int k = 0; k < 1000; k++) {
    const V3 nc = random_unit();
    const double tilt = 2.0 * c.K.zeta_crit / R_GRAIN;
    ContactState st = {unit(-1.0 * nc + tilt * random_unit()), unit(nc + tilt * random_unit()),
                       2.0 * c.K.phi_crit * u(rng)};
    const Displacements d = displacements(st, nc, R_GRAIN, R_GRAIN, c.S.R);
    const double rinv = 1.0 / (2.0 * R_GRAIN - c.S.delta0);
    ChannelLoad load[NCHANNEL];
    tangential_load(st, d, nc, rinv, R_GRAIN, R_GRAIN, c.S.R, c.K, load);
    V3 F = {0, 0, 0}, M1 = F, M2 = F, Fs = F, M1s = F, M2s = F;
    double U[NCHANNEL] = {0, 0, 0}, scale = 0.0;
    add_tangential_loads(st, d, nc, rinv, R_GRAIN, R_GRAIN, c.S.R, c.K, true, F, M1, M2, U);
    for (int ch = 0; ch < NCHANNEL; ch++) {
      Fs = Fs + load[ch].F1;
      M1s = M1s + load[ch].M1;
      M2s = M2s + load[ch].M2;
      worst = std::max(worst, std::fabs(U[ch] - load[ch].U) / (std::fabs(load[ch].U) + 1e-300));
      scale = std::max({scale, norm(load[ch].M1), norm(load[ch].M2)});
    }
    worst = std::max({worst, norm(F - Fs) / norm(Fs), norm(M1 - M1s) / scale,
                      norm(M2 - M2s) / scale});
  }
  check(worst < 1e-14, "loads summed in one pass = the channels' loads summed (relative)",
        worst, 0.0, 1e-14);
}

// the tangential step four contacts at a time (jkr_dt_lanes.h) gives each contact the bits
// of contact_step() alone: 203 contacts (not a multiple of four), compressed and stretched,
// damped, turning slowly and beyond the series, within and beyond every elastic limit
static void lanes_equal_one_contact()
{
  const ContactConstants c =
      contact_constants(ice(true, true, true, 5e-12), R_GRAIN, R_GRAIN);
  const StateLayout L = state_layout(state_fields(ice(true, true, true, 5e-12)));
  const double dt = 4.0e-12;
  constexpr int N = 203;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_unit = [&]() { return unit(V3{u(rng), u(rng), u(rng)}); };
  static JKRDT::TangentialLanes<N> lanes;
  ContactMotion m[N];
  ContactResult one[N], four[N];
  double alone[N][8], laned[N][8], delta[N];
  int clamped = 0, fast = 0;
  for (int e = 0; e < N; e++) {
    const V3 nc = random_unit();
    delta[e] = c.S.delta0 * (0.5 + 1.5 * u(rng));    // -delta0 ... 2 delta0, past -delta_c
    m[e].r = 2.0 * R_GRAIN - delta[e];
    m[e].rinv = 1.0 / m[e].r;
    m[e].d12 = m[e].r * nc;
    m[e].v12 = 0.5 * V3{u(rng), u(rng), u(rng)};
    const double spin = (e % 7 == 0 ? 5e9 : 5e8);    // |omega| dt up to 0.02 or 0.002
    m[e].w1 = spin * V3{u(rng), u(rng), u(rng)};
    m[e].w2 = spin * V3{u(rng), u(rng), u(rng)};
    m[e].vn = dot(m[e].v12, nc);
    const double tilt = 3.0 * c.K.zeta_crit / R_GRAIN * std::fabs(u(rng));
    const ContactState st = {unit(-1.0 * nc + tilt * random_unit()),
                             unit(nc + tilt * random_unit()), 1.5 * c.K.phi_crit * u(rng)};
    double values[8] = {1e-9 * u(rng)};
    store_state(values, L, st);
    std::copy(values, values + 8, alone[e]);
    std::copy(values, values + 8, laned[e]);
    contact_step(c, L, m[e], delta[e], dt, false, false, true, alone[e], one[e]);
    // as the pair loop: a contact that breaks takes contact_step(), the others a lane
    if (delta[e] < -c.S.delta_c)
      contact_step(c, L, m[e], delta[e], dt, false, false, true, laned[e], four[e]);
    else
      contact_normal_part(c, L, m[e], delta[e], dt, false, false, true, laned[e], four[e]);
    clamped += one[e].lossy && one[e].loss[LOSS_SLIDE] + one[e].loss[LOSS_ROLL] +
        one[e].loss[LOSS_TWIST] != 0.0;
    fast += e % 7 == 0;
  }
  int count = 0;
  for (int e = 0; e < N; e++)
    if (!(delta[e] < -c.S.delta_c)) lanes.put(count++, m[e], laned[e], L, four[e]);
  lanes.step(count, c, L, dt, true);
  int differ = 0;
  for (int e = 0; e < N; e++) {
    const ContactResult &a = one[e], &b = four[e];
    const double x[] = {a.F1.x, a.F1.y, a.F1.z, a.M1.x, a.M1.y, a.M1.z, a.M2.x, a.M2.y, a.M2.z,
                        a.U_n, a.U[0], a.U[1], a.U[2], a.loss[0], a.loss[1], a.loss[2],
                        a.loss[3], a.loss[4]};
    const double y[] = {b.F1.x, b.F1.y, b.F1.z, b.M1.x, b.M1.y, b.M1.z, b.M2.x, b.M2.y, b.M2.z,
                        b.U_n, b.U[0], b.U[1], b.U[2], b.loss[0], b.loss[1], b.loss[2],
                        b.loss[3], b.loss[4]};
    for (int k = 0; k < 18; k++) differ += std::memcmp(&x[k], &y[k], sizeof(double)) != 0;
    for (int k = 0; k < 8; k++) differ += std::memcmp(&alone[e][k], &laned[e][k], 8) != 0;
    differ += (a.broken != b.broken) + (a.lossy != b.lossy);
  }
  check(differ == 0 && clamped > 20 && fast > 20 && count < N,
        "tangential step in lanes of four = one contact alone (values that differ)", differ, 0,
        0);
}

// the per-contact state as the kernel declares it: a full frictional contact with damping
// stores F_D, n1, n2 and phi (8 values); switching the channels off and on keeps the fields
// both layouts have and zeroes the others; swapping the particles swaps n1 and n2 only
static void state_layouts()
{
  Coefficients P = ice(true, true, true, 5e-12);
  const StateLayout all = state_layout(state_fields(P));
  P.sliding = P.rolling = P.twisting = 0;
  const StateLayout damped = state_layout(state_fields(P));
  const double v[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  double w[8], back[8];
  relayout(v, all, w, damped);
  relayout(w, damped, back, all);
  const double want[8] = {1, 0, 0, 0, 0, 0, 0, 0};
  int wrong = (all.dnum != 8) + (damped.dnum != 1);
  for (int k = 0; k < 8; k++) wrong += back[k] != want[k];
  double swapped[8];
  std::copy(v, v + 8, swapped);
  swap_particles(swapped, all);
  const double want_swapped[8] = {1, 5, 6, 7, 2, 3, 4, 8};
  for (int k = 0; k < 8; k++) wrong += swapped[k] != want_swapped[k];
  check(wrong == 0, "state layouts: sizes, relayout both ways, particles swapped (values wrong)",
        wrong, 0, 0);
}

int main()
{
  force_against_eq5();
  sqrt_radius_solver();
  clamps();
  setup_changes_nothing();
  angular_momentum();
  elastic_oscillation();
  fast_forms();
  lanes_equal_one_contact();
  state_layouts();
  std::printf("%d failed\n", failures);
  return failures;
}
