/* jkr/dt: one contact over one step, the whole interaction model of Wada et
   al. (2007) in one function: contact_step().

   It takes one contact's constants (type pair and radii), its geometry,
   velocities and spins, and its stored state, and returns the force and
   torques, the new state and what the step dissipated, by channel. No
   LAMMPS types: it is read against the paper's equations and unit-tested
   without LAMMPS (tests/kernel/test_contact_kernel.cpp); PairJKRDT::compute
   is the neighbor-list loop around it.

   Particle 1 is the atom with the smaller ID; n_c = (x1 - x2) / |x1 - x2|,
   eq. (9); v_n > 0 when the particles separate.

   Order within a step (after the drift of velocity Verlet, with v and
   omega at their half-step values):
     1. normal: eq. (4) for the contact radius, the force of eq. (5), the
        damping of eq. (A.5); formation and separation (section 2.1) book
        the jump of U_n as the step meets it (event_loss in jkr_dt_normal.h)
     2. tangential (section 2.2): the pointers turn with their particles,
        n <- turned(n, omega dt); phi += (omega1 - omega2) . n_c dt with n_c
        at the half step; displacements beyond their limits are clamped
        (eqs. 42, A8); the loads of eqs. (14), (17), (23), (27) follow from
        the clamped state
   A contact that forms gets n1 = -n_c, n2 = n_c, phi = 0. The force
   evaluation of a run's set-up (setup = true) moves nothing, clamps nothing
   and books nothing, so that a run continued from a restart file equals the
   uninterrupted one bit for bit.

   Energy: a step that clamps or breaks books, per channel, the difference
   between the work the loads did (trapezoid over the step, which is what
   velocity Verlet gives the kinetic energy) and the change of the channel's
   potential (step_dissipation in jkr_dt_tangential.h). The state at the
   start of the step is the stored one, at positions x - v dt.              */

#ifndef JKR_DT_CONTACT_H
#define JKR_DT_CONTACT_H

#include "jkr_dt_normal.h"
#include "jkr_dt_tangential.h"

namespace JKRDT {

// the normal channels of the ledger (section 2.1 and eq. A.5), declared once: X(enum, name)
#define JKRDT_NORMAL_CHANNELS(X) X(FORM_BREAK, "events") X(DAMPING, "damping")

// where a step's dissipation goes: the columns of the energy ledger, a normal channel's
// or a tangential one's (LOSS_SLIDE, LOSS_ROLL, LOSS_TWIST, from LOSS_TANGENTIAL on)
#define JKRDT_LOSS_ENUM(e, ...) LOSS_##e,
enum Loss { JKRDT_NORMAL_CHANNELS(JKRDT_LOSS_ENUM) JKRDT_TANGENTIAL_CHANNELS(JKRDT_LOSS_ENUM) NLOSS };
#undef JKRDT_LOSS_ENUM
constexpr int LOSS_TANGENTIAL = NLOSS - NCHANNEL;
static_assert(LOSS_TANGENTIAL + SLIDE == LOSS_SLIDE && LOSS_TANGENTIAL + TWIST == LOSS_TWIST,
              "the tangential losses follow the normal ones, in the channels' order");
// the ledger's columns: the losses, then the contacts made and cut in a run's steps (N_con
// and N_cut of the 3D BPCA paper, App. C.2: formation at delta >= 0, breaking at delta <
// -delta_c, section 2.1), half of each event to each atom, so that every rank count sums
// them exactly
enum LedgerColumn { LEDGER_MADE = NLOSS, LEDGER_CUT, NLEDGER };
// compute pair jkr/dt's values: U_n, the tangential potentials, the losses, the bonded
// contacts, and the contacts made and cut
enum PairValue {
  VALUE_U_N = 0,
  VALUE_U_TANGENTIAL,
  VALUE_LOSS = VALUE_U_TANGENTIAL + NCHANNEL,
  VALUE_CONTACTS = VALUE_LOSS + NLOSS,
  VALUE_MADE,
  VALUE_CUT,
  NVALUE
};
// ... and their names (Python's jkrdt.ledger.VALUES, the manual's "Output")
#define JKRDT_NAME(e, name, ...) name,
#define JKRDT_POTENTIAL(e, name, potential) potential,
constexpr const char *VALUE_NAME[] = {"U_n", JKRDT_TANGENTIAL_CHANNELS(JKRDT_POTENTIAL)
                                      JKRDT_NORMAL_CHANNELS(JKRDT_NAME)
                                      JKRDT_TANGENTIAL_CHANNELS(JKRDT_NAME) "contacts", "made",
                                      "cut"};
#undef JKRDT_NAME
#undef JKRDT_POTENTIAL
static_assert(sizeof VALUE_NAME / sizeof VALUE_NAME[0] == NVALUE, "a name per value");

// the coefficients of one type pair, after defaults and mixing
struct Coefficients {
  double gamma;       // surface energy
  double a0_coef;     // (9 pi gamma / E*)^(1/3): a0 = a0_coef R^(2/3), eq. (1)
  double damp_coef;   // 2 tvis E* / nu^2: F_D = damp_coef a v_n, eq. (A.5); 0 = no damping
  double xi_crit;     // critical rolling displacement (NaN if rolling is off)
  double ks_coef;     // k_s / a0 = 8 G* (times ks_scale), eq. (12)
  double zeta_coef;   // zeta_crit / a0 = Gred / (16 pi G*), eqs. (35)-(36)
  double k_r;         // 4 F_c / R = 12 pi gamma (times kr_scale), eq. (22)
  double kt_coef;     // k_t / a0^3 = 16/3 Gred (times kt_scale), eq. (26)
  int sliding, rolling, twisting;
  int damp_tension;    // 1: F_D of eq. (A.5) at every delta; 0: only while compressed (delta >= 0)
  bool tangential() const { return sliding || rolling || twisting; }
};

// everything of one contact that depends only on its type pair and two radii
struct ContactConstants {
  NormalScales S;
  double r1, r2;
  double radsum;        // r1 + r2: the pair touches at |x1 - x2| = radsum, eq. (3)
  double inv_delta0;    // 1 / delta0
  double inv_delta_c;   // 1 / delta_c
  double u_unit;        // F_c delta_c, the unit of U_n in eq. (6)
  double damp;          // damp_coef a0: F_D = damp y^2 v_n, eq. (A.5) with a = y^2 a0
  bool damp_tension;    // F_D also while the contact is stretched (delta < 0)
  Tangential K;
  bool tangential;
};

inline ContactConstants contact_constants(const Coefficients &P, double r1, double r2)
{
  ContactConstants c;
  c.S = normal_scales(r1, r2, P.gamma, P.a0_coef);
  c.r1 = r1;
  c.r2 = r2;
  c.radsum = r1 + r2;
  c.inv_delta0 = 1.0 / c.S.delta0;
  c.inv_delta_c = 1.0 / c.S.delta_c;
  c.u_unit = c.S.F_c * c.S.delta_c;
  c.damp = P.damp_coef * c.S.a0;
  c.damp_tension = P.damp_tension != 0;
  const double a0 = c.S.a0;
  c.K.sliding = P.sliding;
  c.K.rolling = P.rolling;
  c.K.twisting = P.twisting;
  c.K.k_s = P.ks_coef * a0;                  // eq. (12)
  c.K.zeta_crit = P.zeta_coef * a0;          // eq. (36)
  c.K.k_r = P.k_r;                           // eq. (22)
  c.K.xi_crit = P.xi_crit;
  c.K.k_t = P.kt_coef * a0 * a0 * a0;        // eq. (26)
  c.K.phi_crit = PHI_CRIT;                   // eq. (38)
  c.tangential = P.tangential();
  return c;
}

// the same numbers in every constant (NaN, a channel's unused limit, equals NaN)
inline bool same_constants(const ContactConstants &a, const ContactConstants &b)
{
  const double x[] = {a.S.R, a.S.a0, a.S.delta0, a.S.delta_c, a.S.F_c, a.r1, a.r2, a.damp,
                      a.K.k_s, a.K.zeta_crit, a.K.k_r, a.K.xi_crit, a.K.k_t, a.K.phi_crit};
  const double y[] = {b.S.R, b.S.a0, b.S.delta0, b.S.delta_c, b.S.F_c, b.r1, b.r2, b.damp,
                      b.K.k_s, b.K.zeta_crit, b.K.k_r, b.K.xi_crit, b.K.k_t, b.K.phi_crit};
  for (int k = 0; k < 14; k++)
    if (!(x[k] == y[k] || (std::isnan(x[k]) && std::isnan(y[k])))) return false;
  return a.K.sliding == b.K.sliding && a.K.rolling == b.K.rolling &&
      a.K.twisting == b.K.twisting && a.damp_tension == b.damp_tension;
}

// where a contact's stored values sit: offsets into its values, -1 = not stored
struct StateLayout {
  int fd = -1;          // F_D of eq. (A.5) at the last step
  int pointers = -1;    // n1, n2 (6 values)
  int phi = -1;         // twisting angle
  int dnum = 0;         // values per contact
};

/* ----------------------------------------------------------------------
   the per-contact state, declared once: the fields a contact can store,
   their sizes, which fields a type pair's coefficients need, and where
   they sit among a contact's values when a set of fields (a mask, one bit
   per field) is stored. The contact fix stores the values without knowing
   what they are; the kernel and the pair read them through a StateLayout.
     FIELD_DAMPING_FORCE  F_D of eq. (A.5) at the last step     (tvis > 0)
     FIELD_POINTERS       the contact pointers n1, n2, sec. 2.2.4 (sliding or rolling)
     FIELD_TWIST          the twisting angle phi, eq. (24)      (twisting)
------------------------------------------------------------------------- */

enum StateField { FIELD_DAMPING_FORCE = 0, FIELD_POINTERS, FIELD_TWIST, NFIELD };
constexpr int FIELD_SIZE[NFIELD] = {1, 6, 1};

inline int state_fields(const Coefficients &P)
{
  int mask = 0;
  if (P.damp_coef > 0.0) mask |= 1 << FIELD_DAMPING_FORCE;
  if (P.sliding || P.rolling) mask |= 1 << FIELD_POINTERS;
  if (P.twisting) mask |= 1 << FIELD_TWIST;
  return mask;
}

inline StateLayout state_layout(int mask)
{
  int offset[NFIELD], n = 0;
  for (int f = 0; f < NFIELD; f++) {
    offset[f] = ((mask >> f) & 1) ? n : -1;
    if (offset[f] >= 0) n += FIELD_SIZE[f];
  }
  return {offset[FIELD_DAMPING_FORCE], offset[FIELD_POINTERS], offset[FIELD_TWIST], n};
}

inline int field_offset(const StateLayout &L, int field)
{
  return field == FIELD_DAMPING_FORCE ? L.fd : field == FIELD_POINTERS ? L.pointers : L.phi;
}

// a contact's values stored under layout a, written under layout b: the fields both
// store are copied, the others are 0
inline void relayout(const double *from, const StateLayout &a, double *to, const StateLayout &b)
{
  for (int k = 0; k < b.dnum; k++) to[k] = 0.0;
  for (int f = 0; f < NFIELD; f++) {
    const int src = field_offset(a, f), dst = field_offset(b, f);
    if (src >= 0 && dst >= 0)
      for (int k = 0; k < FIELD_SIZE[f]; k++) to[dst + k] = from[src + k];
  }
}

// the contact's particles swap roles (the order of their IDs changed): n1 <-> n2; F_D
// and phi ((omega1 - omega2) . n_c) stay as they are
inline void swap_particles(double *values, const StateLayout &L)
{
  if (L.pointers < 0) return;
  for (int k = 0; k < 3; k++) {
    const double t = values[L.pointers + k];
    values[L.pointers + k] = values[L.pointers + 3 + k];
    values[L.pointers + 3 + k] = t;
  }
}

// the contact's pointers were set (false for a contact formed while no channel needed them)
inline bool traced(const double *values, const StateLayout &L)
{
  if (L.pointers < 0) return true;
  const V3 n1 = vec(values + L.pointers);
  return dot(n1, n1) > 0.0;
}

// the stored tangential state; false if the pointers were never set
inline bool load_state(const double *values, const StateLayout &L, ContactState &c)
{
  c.n1 = {0.0, 0.0, 0.0};
  c.n2 = c.n1;
  c.phi = 0.0;
  if (L.pointers >= 0) {
    c.n1 = vec(values + L.pointers);
    c.n2 = vec(values + L.pointers + 3);
  }
  if (L.phi >= 0) c.phi = values[L.phi];
  return traced(values, L);
}

inline void store_state(double *values, const StateLayout &L, const ContactState &c)
{
  if (L.pointers >= 0) {
    store(c.n1, values + L.pointers);
    store(c.n2, values + L.pointers + 3);
  }
  if (L.phi >= 0) values[L.phi] = c.phi;
}

// the motion of a contact over the step
struct ContactMotion {
  V3 d12;        // x1 - x2
  double r;      // |x1 - x2|
  double rinv;   // 1 / r
  V3 v12;        // v1 - v2 at the half step
  V3 w1, w2;     // omega1, omega2 at the half step
  double vn;     // v12 . d12 / r, > 0 when separating
};

struct ContactResult {
  V3 F1;                 // force on particle 1; particle 2 gets -F1
  V3 M1, M2;             // torques on particles 1 and 2
  double U_n;            // eq. (6), when energy was asked for
  double U[NCHANNEL];    // eqs. (11), (21), (25)
  double loss[NLOSS];    // energy dissipated in this step by channel, whole contact
  bool lossy;            // some loss[] may be non-zero
  bool broken;           // the contact separated in this step
};

/* ----------------------------------------------------------------------
   separation (section 2.1): the contact was last evaluated one step
   earlier, at delta_prev = delta + v_n dt (straight-line relative motion
   over the step), held no further than the break point -delta_c
------------------------------------------------------------------------- */

inline double breaking_loss(double delta, double vn, double dt, const NormalScales &S)
{
  const double delta_prev = std::fmax(delta + vn * dt, -S.delta_c);
  const double y = contact_sqrt_radius(delta_prev / S.delta0);
  const double u_prev = S.F_c * S.delta_c * normal_potential_ratio(y);
  const double f_prev = S.F_c * normal_force_ratio(y);
  return event_loss(u_prev, 0.0, f_prev, vn, dt);
}

/* ----------------------------------------------------------------------
   a step that clamps or breaks books, per channel, what the loads' work over
   the step and the change of the channel's potential leave over
   (step_dissipation). now, d: the state the step leaves and its
   displacements (unused when the contact broke). Rare: kept out of line,
   and given copies, so that the common step's values stay in registers.
------------------------------------------------------------------------- */

struct ChannelLosses {
  double loss[NCHANNEL];
};

[[gnu::noinline, gnu::cold]] inline ChannelLosses book_tangential_step(
    const ContactConstants &c, const ContactMotion m, double dt, const ContactState before,
    const ContactState now, const Displacements d, bool broken)
{
  const Tangential &K = c.K;
  const double R = c.S.R;
  const V3 nc = m.rinv * m.d12;    // eq. (9)
  ChannelLoad load[NCHANNEL], prev[NCHANNEL];
  if (broken)
    for (int ch = 0; ch < NCHANNEL; ch++) load[ch] = {0.0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  else
    tangential_load(now, d, nc, m.rinv, c.r1, c.r2, R, K, load);        // eqs. (14)-(27)
  const V3 dx12 = dt * m.v12;
  const V3 dtheta1 = dt * m.w1, dtheta2 = dt * m.w2;
  const V3 d12_before = m.d12 - dx12;
  const double rinv_before = 1.0 / norm(d12_before);
  tangential_load(before, rinv_before * d12_before, rinv_before, c.r1, c.r2, R, K, prev);
  ChannelLosses booked;
  for (int ch = 0; ch < NCHANNEL; ch++) {
    const double w_before = channel_work(prev[ch], dx12, dtheta1, dtheta2);
    const double w_after = channel_work(load[ch], dx12, dtheta1, dtheta2);
    booked.loss[ch] = step_dissipation(prev[ch].U, w_before, load[ch].U, w_after);
  }
  return booked;
}

/* ----------------------------------------------------------------------
   eq. (24) over one step: the increment (omega1 - omega2) . n_c dt of phi,
   n_c at the half step: (d12 - h) / |d12 - h| with h = (v1 - v2) dt/2, to
   first order in h / r (the error, (h / r)^2 of one increment, is third
   order in dt). One contact, or a lane of contacts (V3T)
------------------------------------------------------------------------- */

template <class T>
inline T twist_increment(const V3T<T> &d12, const V3T<T> &v12, const V3T<T> &w1,
                         const V3T<T> &w2, const T &rinv, const V3T<T> &nc, double dt)
{
  const V3T<T> h = (0.5 * dt) * v12;
  const V3T<T> nc_half = ((1.0 + dot(nc, h) * rinv) * rinv) * (d12 - h);
  return dt * dot(w1 - w2, nc_half);
}

/* ----------------------------------------------------------------------
   the tangential channels over one step (section 2.2); adds their loads
   to the result, books clamps and, for a contact that breaks, the springs'
   energy
------------------------------------------------------------------------- */

[[gnu::always_inline]] inline void tangential_step(const ContactConstants &c,
                                                   const StateLayout &L, const ContactMotion &m,
                                                   double dt, bool setup, bool formed,
                                                   bool breaking, bool energy, double *state,
                                                   ContactResult &out)
{
  const Tangential &K = c.K;
  const double R = c.S.R;
  const V3 nc = m.rinv * m.d12;    // eq. (9)

  ContactState before;
  const bool traced = !formed && load_state(state, L, before);
  ContactState now = before;
  if (!traced) {
    now = {-nc, nc, 0.0};    // section 2.2.4: n1(t0) = -n_c(t0), n2 = n_c
  } else if (!setup) {
    turned(now.n1, dt * m.w1, now.n2, dt * m.w2);
    if (K.twisting) now.phi += twist_increment(m.d12, m.v12, m.w1, m.w2, m.rinv, nc, dt);
  }

  // a set-up evaluates the stored state as it is: the clamp of eqs. (42), (A8) is exact
  // to second order only, so clamping again would move a contact the last step left on
  // its plateau, and a run continued from a restart file would leave the uninterrupted one
  Displacements d;                                                       // eqs. (8)-(20)
  int clamped = 0;
  if (!breaking) {
    if (setup)
      d = displacements(now, nc, c.r1, c.r2, R);
    else
      clamped = clamp_to_elastic_limits(now, nc, c.r1, c.r2, R, K, d);
  }
  if (traced && !setup && (breaking || clamped)) {
    const ChannelLosses booked =
        book_tangential_step(c, m, dt, before, now, breaking ? Displacements{} : d, breaking);
    for (int ch = 0; ch < NCHANNEL; ch++) out.loss[LOSS_TANGENTIAL + ch] += booked.loss[ch];
    out.lossy = true;
  }
  if (breaking) return;
  // the loads as every step computes them, so that a set-up reproduces the step's loads
  // bit for bit
  store_state(state, L, now);
  add_tangential_loads(now, d, nc, m.rinv, c.r1, c.r2, R, K, energy, out.F1, out.M1, out.M2,
                       out.U);                                           // eqs. (14)-(27)
}

/* ----------------------------------------------------------------------
   the tangential step of tangential_step() on its common path, for a lane
   of contacts at once (T = Lanes4, one contact per lane, one set of
   constants): a traced contact, not a set-up, not breaking, whose pointers
   turn by the series and whose displacements stay within their limits. It
   is made of the same functions as tangential_step(), so each lane has the
   bits that tangential_step() gives its contact. s: the stored state in,
   the state after the step out; adds the loads to F1, M1, M2 and (energy)
   the potentials to U. Returns the lanes that stayed on the common path;
   the others' results are not valid (their contacts take
   tangential_step(), which clamps and books).
------------------------------------------------------------------------- */

template <class T>
inline auto tangential_common_step(const ContactConstants &c, const V3T<T> &d12,
                                   const V3T<T> &v12, const V3T<T> &w1, const V3T<T> &w2,
                                   const T &rinv, double dt, bool energy, ContactStateT<T> &s,
                                   V3T<T> &F1, V3T<T> &M1, V3T<T> &M2, T U[NCHANNEL])
{
  const Tangential &K = c.K;
  const double R = c.S.R;
  const V3T<T> nc = rinv * d12;    // eq. (9)
  const V3T<T> w1dt = dt * w1, w2dt = dt * w2;
  const T t1 = dot(w1dt, w1dt), t2 = dot(w2dt, w2dt);
  auto on = (t1 < TURN_SERIES_T2) & (t2 < TURN_SERIES_T2);
  s.n1 = turned_series(s.n1, w1dt, t1);    // section 2.2.4
  s.n2 = turned_series(s.n2, w2dt, t2);
  if (K.twisting) s.phi = s.phi + twist_increment(d12, v12, w1, w2, rinv, nc, dt);
  const DisplacementsT<T> d = displacements(s, nc, c.r1, c.r2, R);    // eqs. (8)-(20)
  // within the elastic limits (the clamps of eqs. 42, A8 would not act)
  if (K.sliding) on &= !sliding_beyond(K, dot(d.zeta, d.zeta));
  if (K.rolling) on &= !rolling_beyond(K, dot(d.xi, d.xi));
  if (K.twisting) on &= !twisting_beyond(K, s.phi);
  add_tangential_loads(s, d, nc, rinv, c.r1, c.r2, R, K, energy, F1, M1, M2, U);
  return on;
}

/* ----------------------------------------------------------------------
   the normal interaction over one step (section 2.1 and eq. A.5): all a
   contact without tangential channels needs, in a result small enough to
   stay in registers. delta = r1 + r2 - r, eq. (3); formed: the pair was not
   bonded before this step (delta >= 0); energy: fill U_n. Reads and writes
   the stored F_D (state[L.fd]) when damped. y_near: the series root of
   eq. (4) at d = delta/delta0 (contact_sqrt_radius_series(d - 1)), where the
   caller has taken it ahead for a block of pairs; it stands for the root
   where the series does (|d - 1| < SERIES_E_MAX), 0 if not taken.
------------------------------------------------------------------------- */

struct NormalResult {
  double f;             // force along x1 - x2 (F_1 = f d12 / r): eq. (5) minus F_D of eq. (A.5)
  double U_n;           // eq. (6), when energy was asked for or the contact formed
  double loss_event;    // formation or breaking, booked as LOSS_FORM_BREAK
  double loss_damping;  // the work of F_D over the step, booked as LOSS_DAMPING
  bool lossy;           // some loss may be non-zero
  bool broken;          // the contact separated in this step
};

[[gnu::always_inline]] inline void normal_step(const ContactConstants &c,
                                               const StateLayout &L, double vn, double delta,
                                               double dt, bool setup, bool formed,
                                               bool energy, double *state, NormalResult &n,
                                               double y_near = 0.0)
{
  const NormalScales &S = c.S;
  n.f = n.U_n = n.loss_event = n.loss_damping = 0.0;
  n.broken = false;
  n.lossy = !setup && (formed || c.damp > 0.0);
  if (!formed && delta < -S.delta_c) {
    // separation (section 2.1): U_n drops to 0 from its value at the last step
    n.broken = true;
    if (!setup) {
      n.lossy = true;
      n.loss_event = breaking_loss(delta, vn, dt, S);
      if (c.damp > 0.0 && L.fd >= 0) n.loss_damping = 0.5 * dt * state[L.fd] * vn;
    }
    return;
  }
  const double d = delta * c.inv_delta0;
  const double y = (y_near > 0.0 && std::fabs(d - 1.0) < SERIES_E_MAX)
      ? y_near : contact_sqrt_radius(d);                              // eq. (4)
  n.f = S.F_c * normal_force_ratio(y);                             // eq. (5)
  if (energy || (formed && !setup)) n.U_n = c.u_unit * normal_potential_ratio(y);    // eq. (6)
  // contact formation (section 2.1): U_n jumps from 0 to U_n(0)
  if (formed && !setup) n.loss_event = event_loss(0.0, n.U_n, n.f, vn, dt);

  if (c.damp > 0.0 && L.fd >= 0) {    // a damped contact stores F_D (state_fields)
    // eq. (A.5); a run's first evaluation reuses the stored F_D, so that a
    // continued run equals an uninterrupted one. Its work over the step is the
    // trapezoid F_D(n) (v_n(n-1/2) + v_n(n+1/2)) dt / 2 of the two half-kicks
    const double fd_prev = formed ? 0.0 : state[L.fd];
    // (damp_tension off: no F_D while the contact is stretched, delta < 0)
    const double fd = (setup && !formed)          ? fd_prev
        : (delta >= 0.0 || c.damp_tension) ? c.damp * y * y * vn
                                           : 0.0;
    if (!setup) n.loss_damping = 0.5 * dt * (fd_prev + fd) * vn;
    state[L.fd] = fd;
    n.f -= fd;
  }
}

/* ----------------------------------------------------------------------
   one contact over one step: the normal interaction, then the tangential
   channels. delta = r1 + r2 - r, eq. (3); formed: the pair was not bonded
   before this step (delta >= 0); energy: fill U_n and U.
   The state (L.dnum values) is read and written in place.
   contact_normal_part() is its first half, which the pair loop also calls
   alone for a contact whose tangential step it takes in a lane
   (jkr_dt_lanes.h); it returns whether the contact broke.
------------------------------------------------------------------------- */

[[gnu::always_inline]] inline bool contact_normal_part(const ContactConstants &c,
                                                       const StateLayout &L,
                                                       const ContactMotion &m, double delta,
                                                       double dt, bool setup, bool formed,
                                                       bool energy, double *state,
                                                       ContactResult &out, double y_near = 0.0)
{
  out.M1 = out.M2 = {0.0, 0.0, 0.0};
  for (int ch = 0; ch < NCHANNEL; ch++) out.U[ch] = 0.0;
  for (int l = 0; l < NLOSS; l++) out.loss[l] = 0.0;
  if (formed)
    for (int k = 0; k < L.dnum; k++) state[k] = 0.0;

  NormalResult n;
  normal_step(c, L, m.vn, delta, dt, setup, formed, energy, state, n, y_near);
  out.U_n = n.U_n;
  out.loss[LOSS_FORM_BREAK] = n.loss_event;
  out.loss[LOSS_DAMPING] = n.loss_damping;
  out.lossy = n.lossy;
  out.broken = n.broken;
  out.F1 = n.broken ? V3{0.0, 0.0, 0.0} : (n.f * m.rinv) * m.d12;
  return n.broken;
}

[[gnu::always_inline]] inline void contact_step(const ContactConstants &c,
                                                const StateLayout &L, const ContactMotion &m,
                                                double delta, double dt, bool setup,
                                                bool formed, bool energy, double *state,
                                                ContactResult &out, double y_near = 0.0)
{
  const bool broken =
      contact_normal_part(c, L, m, delta, dt, setup, formed, energy, state, out, y_near);
  if (c.tangential) tangential_step(c, L, m, dt, setup, formed, broken, energy, state, out);
}

}    // namespace JKRDT

#endif
