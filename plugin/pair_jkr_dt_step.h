/* jkr/dt: one pair of the neighbor list over one step, as the pair loop
   (pair_jkr_dt_loop.cpp) takes it, written once for every path.

   The steps of a pair, in the order the loop takes them:
     1. the distance test            Block::fill, a block of the list's pairs at a time:
                                     the pairs in contact or touching go on
     2. its constants                Constants: per scene, per type pair or per radii
     3. its motion and the guards    PairStep::motion, PairStep::guards
     4. its contact over the step    PairStep::advance: the contact kernel
                                     (jkr_dt_contact.h), or its normal part now and the
                                     tangential step in a lane (jkr_dt_lanes.h)
     5. its loads and dissipation    PairStep::apply (forces, torques, the ledger) and
                                     PairStep::tally (energy, virial)
   PairStep::evaluate is steps 2-4, PairStep::deliver step 5.

   PairStep<TANGENTIAL, LEAN>. LEAN is the common step: a contact that held at the
   last step between two atoms of this thread, none departed, in a step that is no
   set-up and sums no energy or virial. It is this same code with those facts known at
   compile time, so that the others' bookkeeping (formation, set-up, departed grains,
   ghost atoms, other threads, tallies) folds away; the loop runs it out of line,
   where its few values stay in registers. It stops (Eval::STOP, nothing of the pair
   applied) at a pair with more to do (a guard, a contact that breaks, one without
   pointers yet), which the general step then takes from the start, with the same bits.
   TANGENTIAL: some type pair has a tangential channel.

   Energy. pe holds the contact potentials U_n + U_s + U_r + U_t, eqs. (6),
   (11), (21), (25). The energy that leaves the mechanical budget is booked
   per channel in the contact fix's per-atom ledger, half to each atom of the
   contact (PairStep::apply):
     formation, breaking  the jump of U_n (section 2.1) as the integrator
                meets it: see event_loss() in jkr_dt_normal.h
     damping    the work of F_D of eq. (A.5) across the two half-kicks of
                velocity Verlet that apply it: F_D(n) (v_rel(n-1/2) + v_rel(n+1/2)) dt / 2
     sliding, rolling, twisting  the inelastic clamps of section 2.2.5 and
                the springs' energy when a contact breaks
   so that ke + erotate + pe + (dissipated) stays constant.
   Contacts present when a run starts (the force evaluation of setup) are
   taken as given: they book nothing.                                        */

#ifndef JKR_DT_PAIR_STEP_H
#define JKR_DT_PAIR_STEP_H

#include "pair_jkr_dt.h"

#include "jkr_dt_lanes.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace LAMMPS_NS {

// what a pair's step reads and writes: the atoms, the step, the contact store (flat:
// LAMMPS's per-atom 3-vectors are contiguous, one load less per neighbor)
struct PairJKRDT::View {
  const double *x, *v, *omega, *radius;
  const tagint *tag;
  const int *type, *mask;
  double *f, *torque;
  double **ledger;                 // the contact store's per-atom rows
  unsigned char *bonded;           // per slot of the contact store
  double *slot_values;             // per slot, layout.dnum values
  JKRDT::StateLayout layout;
  const int *thread_of;            // the owning thread of each owned atom; null: one thread
  int me;                          // this thread
  int nlocal;
  int departed;                    // the mask bit of the departed group; 0: none
  int eflag;
  bool setup;                      // the force evaluation of a run's set-up
  bool tally_atoms, eflag_global, vflag_global, vflag_either;
  double dt, half_skin;
  const JKRDT::ContactConstants *scene_K;    // one set for the scene (BY_SCENE), else null
  bool lanes;    // the tangential step of a block's contacts four at a time: one set of
                 // constants, contacts that store their pointers

  // a grain of the pair is in a fragment that has departed for good
  bool departed_pair(int p, int q) const { return departed && ((mask[p] | mask[q]) & departed); }
  // atom a is this thread's, to write to directly
  bool mine(int a) const { return !thread_of || thread_of[a] == me; }
};

// where a pair evaluated with other constants than the scene's finds them
struct PairJKRDT::Constants {
  const PairJKRDT &pair;
  ConstantsBy by;
  const double *radius;
  const int *type;
  JKRDT::ContactConstants cached{};    // BY_RADII: the last pair's, reused while they fit
  const Param *last_param = nullptr;
  double last_r1 = -1.0, last_r2 = -1.0;

  const JKRDT::ContactConstants &of(int p, int q)
  {
    if (by == BY_TYPE) return pair.type_constants[type[p] * pair.nstride + type[q]];
    const Param &P = pair.par(type[p], type[q]);
    if (&P != last_param || radius[p] != last_r1 || radius[q] != last_r2) {
      cached = JKRDT::contact_constants(P, radius[p], radius[q]);
      last_param = &P;
      last_r1 = radius[p];
      last_r2 = radius[q];
    }
    return cached;
  }
};

// how evaluate() leaves a pair
enum class PairJKRDT::Eval {
  SKIP,       // nothing to deliver
  DONE,       // deliver() adds its loads
  TROUBLE,    // a guard named it: the loop stops
  LEAN,       // the LEAN step handed it to the lanes: its LEAN deliver() adds its loads
  STOP        // the LEAN step cannot finish it: nothing applied, the general step takes it
};

// a pair of a block, as evaluate() leaves it for deliver()
struct alignas(64) PairJKRDT::Done {
  int p, q, s, owned;    // its atoms (p = particle 1 where that matters), slot, owned atoms
  bool parked, setup, formed;
  JKRDT::ContactMotion m;    // kept here: a lane reads it back (TangentialLanes::put)
  JKRDT::ContactResult out;
};

/* ----------------------------------------------------------------------
   a block of the list's pairs: 16 pairs, so that a block's scratch (these
   arrays, the lanes' inputs, each contact's motion and result) stays in a
   48 KB L1 cache between its passes; at 64 it did not, and the full
   model's loop missed L1 on about 6 writes per pair (callgrind,
   docs/performance.md)
------------------------------------------------------------------------- */

template <bool TANGENTIAL> struct PairJKRDT::Block {
  static constexpr int N = 16;
  int i[N], j[N], slot[N];
  JKRDT::V3 d12[N];
  double rsq[N], radsum[N], r[N], rinv[N], y_near[N];
  Eval eval[N];
  Done done[N];
  JKRDT::TangentialLanes<N> lanes;
  int nlane;    // contacts put in the lanes

  // 1. the distance test from slot s on: the pairs in contact or touching are kept with
  // their separation, and their r and 1/r are then taken for the whole block at once
  // (square roots and divisions that do not wait for one another); returns their number
  int fill(const SlotPair *pairs, int &s, int s_to, const View &w)
  {
    int n = 0;
    for (; s < s_to && n < N; s++) {
      const int p = pairs[s].p, q = pairs[s].q;
      const JKRDT::V3 d = JKRDT::vec(w.x + 3 * p) - JKRDT::vec(w.x + 3 * q);
      const double rr = JKRDT::dot(d, d);
      const double rs = w.scene_K ? w.scene_K->radsum : w.radius[p] + w.radius[q];
      if (!w.bonded[s] && rr > rs * rs) continue;
      i[n] = p;
      j[n] = q;
      slot[n] = s;
      d12[n] = d;
      rsq[n] = rr;
      radsum[n] = rs;
      n++;
    }
    for (int k = 0; k < n; k++) r[k] = std::sqrt(rsq[k]);
    for (int k = 0; k < n; k++) rinv[k] = 1.0 / r[k];
    // and, with one set of constants for the scene, the series root of eq. (4) that a
    // contact near rest takes (normal_step uses it only there)
    if (w.scene_K) {
      const double inv_delta0 = w.scene_K->inv_delta0;
      for (int k = 0; k < n; k++)
        y_near[k] = JKRDT::contact_sqrt_radius_series((radsum[k] - r[k]) * inv_delta0 - 1.0);
    } else {
      std::fill(y_near, y_near + n, 0.0);
    }
    return n;
  }

  // pair k may take the LEAN step: bonded, both atoms this thread's (the list's atom i
  // is; with channels the pair may be stored the other way round), none departed
  bool lean(int k, const View &w) const
  {
    const int p = i[k], q = j[k];
    if (!w.bonded[slot[k]] || q >= w.nlocal || (TANGENTIAL && p >= w.nlocal) ||
        w.departed_pair(p, q))
      return false;
    return w.mine(q) && (!TANGENTIAL || w.mine(p));
  }
};

/* ----------------------------------------------------------------------
   steps 2-5 of one pair (see the top of this file)
------------------------------------------------------------------------- */

template <bool TANGENTIAL, bool LEAN> struct PairJKRDT::PairStep {
  using V3 = JKRDT::V3;
  using K_t = JKRDT::ContactConstants;
  const View w;    // a copy: a store to a force may not alias it
  Constants &by_pair;
  Block<TANGENTIAL> &B;
  Accumulator &acc;
  PairJKRDT &pair;
  double step_max;    // the sums of the steps, in registers while they run
  bigint contact_ends = 0;

  PairStep(const View &view, Constants &K, Block<TANGENTIAL> &block, Accumulator &a,
           PairJKRDT &style) :
      w(view), by_pair(K), B(block), acc(a), pair(style), step_max(a.step_max)
  {
  }
  void hand_over()
  {
    acc.contact_ends += contact_ends;
    acc.step_max = std::max(acc.step_max, step_max);
  }

  [[gnu::always_inline]] const K_t &constants(int p, int q)
  {
    if (LEAN && TANGENTIAL) return *w.scene_K;    // the lanes' LEAN step: the scene's
    return w.scene_K ? *w.scene_K : by_pair.of(p, q);
  }
  void trouble(Trouble::Kind kind, int p, int q, double a, double b, const K_t &K)
  {
    if (w.tag[q] < w.tag[p]) std::swap(p, q);    // name the pair as the other rank does
    acc.trouble = {kind, p, q, a, b, K.S};
  }
  // a guard named the pair: the general step stops the loop there, LEAN leaves it
  Eval stop(Trouble::Kind kind, int p, int q, double a, double b, const K_t &K)
  {
    if (LEAN) return Eval::STOP;
    trouble(kind, p, q, a, b, K);
    return Eval::TROUBLE;
  }

  // steps 2-4 of pair k of the block, into o
  [[gnu::always_inline]] Eval evaluate(int k, Done &o)
  {
    // 2. the pair as follow_slots() stored it, and its constants
    const int p = B.i[k], q = B.j[k], s = B.slot[k];
    const bool bonded = LEAN || w.bonded[s];
    const K_t &K = constants(p, q);
    // a grain of a fragment that has left for good meets nothing, and its own contacts
    // stand still: they are only evaluated, as a set-up does, for their potential energy
    const int owned = LEAN ? 2 : (p < w.nlocal) + (q < w.nlocal);    // half per owned atom
    const bool parked = !LEAN && w.departed_pair(p, q);
    if (parked && !(bonded && w.eflag)) {
      if (bonded) contact_ends += owned;
      return Eval::SKIP;
    }
    const bool setup = !LEAN && (w.setup || parked);
    const bool formed = !bonded;    // delta >= 0 here: contact formation (section 2.1)
    o.p = p;
    o.q = q;
    if (!LEAN) {
      o.s = s;
      o.owned = owned;
      o.parked = parked;
      o.setup = setup;
      o.formed = formed;
    }
    // 3. the motion over the step and the guards
    const double r = B.r[k];
    const double delta = B.radsum[k] - r;    // eq. (3)
    if (!std::isfinite(delta) || r == 0.0) return stop(Trouble::BLOW_UP, p, q, r, 0.0, K);
    if (LEAN && delta < -K.S.delta_c) return Eval::STOP;    // it breaks
    // (the lanes' contacts store their pointers)
    double *state = (LEAN && TANGENTIAL) || w.layout.dnum
        ? w.slot_values + (bigint) s * w.layout.dnum : nullptr;
    if (LEAN && TANGENTIAL && !JKRDT::traced(state, w.layout)) return Eval::STOP;
    motion(k, p, q, o.m);
    const double step = parked ? 0.0 : std::fabs(o.m.vn) * w.dt;
    const Eval guarded = guards(p, q, K, delta, step, setup, formed, o.m.vn);
    if (guarded != Eval::DONE) return guarded;
    // 4.
    return advance(k, o, K, delta, setup, formed, state);
  }

  // x1 - x2, |x1 - x2|, the relative velocity and the spins at the half step
  [[gnu::always_inline]] void motion(int k, int p, int q, JKRDT::ContactMotion &m)
  {
    m.d12 = B.d12[k];
    m.r = B.r[k];
    m.rinv = B.rinv[k];
    m.v12 = JKRDT::vec(w.v + 3 * p) - JKRDT::vec(w.v + 3 * q);
    if (TANGENTIAL) {
      m.w1 = JKRDT::vec(w.omega + 3 * p);
      m.w2 = JKRDT::vec(w.omega + 3 * q);
    }
    m.vn = JKRDT::dot(m.v12, m.d12) * m.rinv;    // > 0 when separating
  }

  // the guards that name a pair the step cannot resolve; DONE: none did
  [[gnu::always_inline]] Eval guards(int p, int q, const K_t &K, double delta, double step,
                                     bool setup, bool formed, double vn)
  {
    if (step > w.half_skin) return stop(Trouble::FAST_PAIR, p, q, vn, 0.0, K);
    if (!setup) step_max = std::max(step_max, step * K.inv_delta_c);
    if (formed && setup && delta >= std::min(w.radius[p], w.radius[q]))
      return stop(Trouble::OVERLAP, p, q, delta, 0.0, K);
    // a contact forms within the step that closes the gap: deeper means it was missed
    if (formed && !setup && delta > 2.0 * step + LATE_SLACK * K.S.delta_c)
      return stop(Trouble::LATE, p, q, delta, step, K);
    return Eval::DONE;
  }

  // 4. the contact over the step: the whole kernel, or its normal part alone, or (the
  // lanes) the normal part now and the tangential step in a lane
  [[gnu::always_inline]] Eval advance(int k, Done &o, const K_t &K, double delta, bool setup,
                                      bool formed, double *state)
  {
    const JKRDT::ContactMotion &m = o.m;
    JKRDT::ContactResult &out = o.out;
    const int energy = LEAN ? 0 : w.eflag;
    if constexpr (!TANGENTIAL) {
      JKRDT::NormalResult nr;
      JKRDT::normal_step(K, w.layout, m.vn, delta, w.dt, setup, formed, energy, state, nr,
                         B.y_near[k]);
      out.F1 = (nr.f * m.rinv) * m.d12;
      out.broken = nr.broken;
      out.lossy = nr.lossy;
      out.loss[JKRDT::LOSS_FORM_BREAK] = nr.loss_event;
      out.loss[JKRDT::LOSS_DAMPING] = nr.loss_damping;
      out.U_n = nr.U_n;
      return Eval::DONE;
    }
    // a lane takes a traced contact's step that is no set-up and does not break
    const bool in_lane = LEAN ||
        (w.lanes && !setup && !formed && !(delta < -K.S.delta_c) &&
         JKRDT::traced(state, w.layout));
    if (!in_lane) {
      JKRDT::contact_step(K, w.layout, m, delta, w.dt, setup, formed, energy, state, out,
                          B.y_near[k]);
      return Eval::DONE;
    }
    JKRDT::contact_normal_part(K, w.layout, m, delta, w.dt, false, false, energy, state, out,
                               B.y_near[k]);
    B.lanes.put(B.nlane++, m, state, w.layout, out);
    return LEAN ? Eval::LEAN : Eval::DONE;
  }

  // 5. the pair's loads and dissipation; false: its force is not finite (the trouble is
  // recorded)
  [[gnu::always_inline]] bool deliver(const Done &o)
  {
    const JKRDT::ContactResult &out = o.out;
    const V3 F1 = out.F1;    // in registers: a store to a force may not alias them
    const bool broken = !LEAN && out.broken, lossy = out.lossy;
    if (!broken && !std::isfinite(F1.x + F1.y + F1.z)) {
      trouble(Trouble::NOT_FINITE, o.p, o.q, 0, 0, constants(o.p, o.q));
      return false;
    }
    if (!LEAN) w.bonded[o.s] = !broken;
    if (LEAN || !o.parked) {
      apply(o, o.p, F1, out.M1, lossy, broken);
      apply(o, o.q, -F1, out.M2, lossy, broken);
    }
    if (broken) return true;
    contact_ends += LEAN ? 2 : o.owned;
    if (!LEAN && (w.eflag || w.vflag_either)) tally(o);
    return true;
  }

  // force on atom a: normal (eq. 5 and A.5) plus sliding (eq. 14), -force on the other;
  // its torque, eqs. (17), (23), (27); half of the step's dissipation, if a is owned
  [[gnu::always_inline]] void apply(const Done &o, int a, const V3 fa_add, const V3 &ma,
                                    bool lossy, bool broken)
  {
    constexpr int nloss = TANGENTIAL ? JKRDT::NLOSS : JKRDT::LOSS_DAMPING + 1;
    if (!LEAN && a >= w.nlocal) return;
    double *fa, *ta, *far_loss = nullptr;
    if (LEAN || w.mine(a)) {
      fa = w.f + 3 * a;
      ta = w.torque + 3 * a;
    } else {    // an owned atom of another thread gets its share through acc.far
      acc.far.push_back(FarLoad{a, {0, 0, 0}, {0, 0, 0}, {}});
      fa = acc.far.back().f;
      ta = acc.far.back().torque;
      far_loss = acc.far.back().loss;
    }
    if (lossy && (LEAN || !o.setup)) {    // the atom's ledger row only when it books
      double *la = far_loss ? far_loss : w.ledger[a];
      for (int l = 0; l < nloss; l++) la[l] += 0.5 * o.out.loss[l];
      // N_con, N_cut (3D BPCA paper, App. C.2): every formation and breaking books a
      // loss, and only in the general step
      if (!LEAN && o.formed) la[JKRDT::LEDGER_MADE] += 0.5;
      if (broken) la[JKRDT::LEDGER_CUT] += 0.5;
    }
    if (broken) return;
    fa[0] += fa_add.x;
    fa[1] += fa_add.y;
    fa[2] += fa_add.z;
    if (TANGENTIAL) {
      ta[0] += ma.x;
      ta[1] += ma.y;
      ta[2] += ma.z;
    }
  }

  // the pair's potential energy and virial, half per owned atom
  void tally(const Done &o)
  {
    const JKRDT::ContactResult &out = o.out;
    const V3 &fp = out.F1, &d12 = o.m.d12;
    const double share = 0.5 * o.owned;
    double u = out.U_n;
    if (TANGENTIAL)
      for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) u += out.U[ch];
    if (w.eflag) {
      acc.upot += share * out.U_n;
      if (TANGENTIAL)
        for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) acc.utan[ch] += share * out.U[ch];
    }
    if (w.tally_atoms) {
      pair.ev_tally_xyz(o.p, o.q, w.nlocal, 0, u, 0.0, fp.x, fp.y, fp.z, d12.x, d12.y, d12.z);
      return;
    }
    // ev_tally_xyz with newton off, by hand: thread-safe into this thread's sums
    if (w.eflag_global) acc.eng += share * u;
    if (w.vflag_global) {
      acc.virial[0] += share * d12.x * fp.x;
      acc.virial[1] += share * d12.y * fp.y;
      acc.virial[2] += share * d12.z * fp.z;
      acc.virial[3] += share * d12.x * fp.y;
      acc.virial[4] += share * d12.x * fp.z;
      acc.virial[5] += share * d12.y * fp.z;
    }
  }
};

}    // namespace LAMMPS_NS

#endif
