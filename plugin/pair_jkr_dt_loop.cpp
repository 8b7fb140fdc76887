/* jkr/dt: the neighbor-list loop, contact formation and breaking, and the
   energy ledger.

   Parallel layout. The style asks for a half neighbor list built as with
   newton off, whatever the global newton setting: a pair with one ghost atom
   is computed on both ranks, and each rank writes forces and contact state
   only for its own atoms. The contact state is kept in list order, one copy
   per pair of this rank's list (FixJKRDTContacts): a pair with a ghost atom
   is kept, and advanced identically, on both ranks, so no reverse
   communication of contact state is ever needed. Each pair is
   evaluated in its canonical orientation (particle 1 = smaller atom ID), so
   the two ranks do the same arithmetic on the same numbers.

   The tangential channels (sliding, rolling, twisting; section 2.2) of a
   contact are advanced in pair_jkr_dt_tangential.cpp; their forces and
   torques are added here.

   Energy. pe holds the contact potentials U_n + U_s + U_r + U_t, eqs. (6),
   (11), (21), (25). The energy that
   leaves the mechanical budget is booked per channel in the contact fix's
   per-atom ledger, half to each atom of the contact:
     formation, breaking  the jump of U_n (section 2.1) as the integrator
                meets it: see event_loss() in jkr_dt_normal.h
     damping    the work of F_D of eq. (A.5) across the two half-kicks of
                velocity Verlet that apply it: F_D(n) (v_rel(n-1/2) + v_rel(n+1/2)) dt / 2
     sliding, rolling, twisting  the inelastic clamps of section 2.2.5 and
                the springs' energy when a contact breaks
   so that ke + erotate + pe + (dissipated) stays constant.
   Contacts present when a run starts (the force evaluation of setup) are
   taken as given: they book nothing.                                        */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"
#include "jkr_dt_lanes.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "memory.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <utility>
#if defined(_OPENMP)
#include <omp.h>
#endif

using namespace LAMMPS_NS;
using Contacts = FixJKRDTContacts;

namespace {
// a lean pair's loads on its two atoms, in the order deliver() adds them: F_1 on atom p and
// -F_1 on q in the flat force array; M_1 and M_2 in the torques (with channels); half of
// each of the step's first nloss losses in each atom's ledger row (when it has any)
inline void add_pair_force(int p, int q, const JKRDT::V3 &F1, double *f)
{
  double *fp = f + 3 * p, *fq = f + 3 * q;
  fp[0] += F1.x;
  fp[1] += F1.y;
  fp[2] += F1.z;
  fq[0] += -F1.x;
  fq[1] += -F1.y;
  fq[2] += -F1.z;
}
inline void add_pair_torques(int p, int q, const JKRDT::V3 &M1, const JKRDT::V3 &M2, double *t)
{
  double *tp = t + 3 * p, *tq = t + 3 * q;
  tp[0] += M1.x;
  tp[1] += M1.y;
  tp[2] += M1.z;
  tq[0] += M2.x;
  tq[1] += M2.y;
  tq[2] += M2.z;
}
inline void book_pair_losses(int p, int q, const double *loss, int nloss, double *const *rows)
{
  for (int side = 0; side < 2; side++) {
    double *la = rows[side ? q : p];
    for (int l = 0; l < nloss; l++) la[l] += 0.5 * loss[l];
  }
}
// a lean loop (an always_inline lambda of the pair loop) called out of line, compiled for
// the pair loop's instruction set
template <class Run, class... A> __attribute__((noinline)) int out_of_line(Run &run, A &&...a)
{
  return run(std::forward<A>(a)...);
}
#if JKRDT_AVX2
template <class Run, class... A>
__attribute__((noinline, target("avx2"))) int out_of_line_avx2(Run &run, A &&...a)
{
  return run(std::forward<A>(a)...);
}
#endif
}    // namespace

void PairJKRDT::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  if (update->laststep != checked_laststep) {    // once per run, 'run N pre no' included
    checked_laststep = update->laststep;
    check_time_step();
  }
  Contacts &C = *fix_contacts;
  if (!C.slots_follow(list)) C.to_slots(list);    // a list built without post_neighbor
  if (slot_pair_made != C.slots_made() || slot_pair_oriented != any_tangential)
    follow_slots();

  const int inum = list->inum;
  const bool tally_atoms = eflag_atom || vflag_atom;
  const int nthreads = (tally_atoms || inum < 64) ? 1 : nthreads_used();
  if ((int) accumulators.size() < nthreads) accumulators.resize(nthreads);
  std::vector<Accumulator> &acc = accumulators;
  for (int t = 0; t < nthreads; t++) {
    Accumulator &a = acc[t];
    a.thread = t;
    a.thread_of = nullptr;    // set below when threaded
    a.far.clear();
    a.upot = a.eng = a.step_max = 0.0;
    a.contact_ends = 0;
    std::fill(a.utan, a.utan + JKRDT::NCHANNEL, 0.0);
    std::fill(a.virial, a.virial + 6, 0.0);
    a.trouble = Trouble();
  }

  const ConstantsBy by = constants_by();
  auto loop = [&](int from, int to, bool tally, Accumulator &a) {
#if JKRDT_AVX2
    if (kernel_avx2) {
      if (any_tangential)
        pair_loop_avx2<true>(from, to, eflag, tally, by, a);
      else
        pair_loop_avx2<false>(from, to, eflag, tally, by, a);
      return;
    }
#endif
    if (any_tangential)
      pair_loop_portable<true>(from, to, eflag, tally, by, a);
    else
      pair_loop_portable<false>(from, to, eflag, tally, by, a);
  };
  if (nthreads == 1) {
    loop(0, inum, tally_atoms, acc[0]);
  } else {
    // the threads take runs of the list with equal shares of its pairs (one per atom
    // counted too), set when it is built (or the thread count changes); equal shares of
    // atoms gave the first of 2 threads about 10 % more pairs (2 x 2500)
    auto from = [&](int t) { return thread_from[t]; };
    if (thread_of_build != neighbor->lastcall || thread_of_threads != nthreads ||
        update->setupflag || (int) thread_of.size() < atom->nlocal) {
      const int *numneigh = list->numneigh, *ilist = list->ilist;
      bigint pairs = 0, seen = 0;
      for (int ii = 0; ii < inum; ii++) pairs += numneigh[ilist[ii]] + 1;
      thread_from.assign(nthreads + 1, inum);
      thread_from[0] = 0;
      for (int ii = 0, t = 1; ii < inum && t < nthreads; ii++) {
        seen += numneigh[ilist[ii]] + 1;
        while (t < nthreads && seen * nthreads >= pairs * t) thread_from[t++] = ii + 1;
      }
      if ((int) thread_of.size() < atom->nlocal) thread_of.resize(atom->nmax);
      for (int t = 0; t < nthreads; t++)
        for (int ii = from(t); ii < from(t + 1); ii++) thread_of[list->ilist[ii]] = t;
      thread_of_build = neighbor->lastcall;
      thread_of_threads = nthreads;
    }
    for (int t = 0; t < nthreads; t++) acc[t].thread_of = thread_of.data();
#if defined(_OPENMP)
#pragma omp parallel num_threads(nthreads)
    {
      const int t = omp_get_thread_num();
      loop(from(t), from(t + 1), false, acc[t]);
    }
#endif
    // what each thread added to other threads' atoms, in thread order: the same
    // partition gives the same sums
    double **f = atom->f, **tq = atom->torque, **ledger = C.ledger;
    for (int t = 0; t < nthreads; t++)
      for (const FarLoad &l : acc[t].far) {
        for (int k = 0; k < 3; k++) {
          f[l.atom][k] += l.f[k];
          tq[l.atom][k] += l.torque[k];
        }
        for (int k = 0; k < JKRDT::NLEDGER; k++) ledger[l.atom][k] += l.loss[k];
      }
  }

  Accumulator &total = acc[0];    // the other threads' sums go into thread 0's
  for (int t = 0; t < nthreads; t++) {
    if (acc[t].trouble.kind != Trouble::NONE) report(acc[t].trouble);
    if (t == 0) continue;
    total.upot += acc[t].upot;
    total.contact_ends += acc[t].contact_ends;
    total.eng += acc[t].eng;
    total.step_max = std::max(total.step_max, acc[t].step_max);
    for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) total.utan[ch] += acc[t].utan[ch];
    for (int k = 0; k < 6; k++) total.virial[k] += acc[t].virial[k];
  }
  step_max = std::max(step_max, total.step_max);
  if (!tally_atoms) {
    if (eflag_global) eng_vdwl += total.eng;
    if (vflag_global)
      for (int k = 0; k < 6; k++) virial[k] += total.virial[k];
  }
  C.rows_changed();
  if (eflag_global) fill_pvector(total.upot, total.utan, 0.5 * total.contact_ends);
}

/* ----------------------------------------------------------------------
   the list's pairs in the contact fix's slot order (ilist, then each
   atom's neighbors), each in the orientation the loop evaluates it in: with
   tangential channels particle 1 is the smaller ID (the state is kept for
   that orientation, and both ranks of a pair with a ghost atom then do the
   same arithmetic), else the list's atom i. IDs change only where the list
   is built anew, so the orientation holds until the slots change.
------------------------------------------------------------------------- */

void PairJKRDT::follow_slots()
{
  const Contacts &C = *fix_contacts;
  const tagint *tag = atom->tag;
  const int inum = list->inum;
  const int *ilist = list->ilist, *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;
  slot_pair.resize(C.slot_first[inum]);
  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    SlotPair *to = slot_pair.data() + C.slot_first[ii];
    for (int jj = 0; jj < numneigh[i]; jj++) {
      const int j = firstneigh[i][jj] & NEIGHMASK;
      to[jj] = any_tangential && tag[j] < tag[i] ? SlotPair{j, i} : SlotPair{i, j};
    }
  }
  slot_pair_made = C.slots_made();
  slot_pair_oriented = any_tangential;
}

/* ----------------------------------------------------------------------
   where the pair loop finds a contact's constants (contact_constants), as
   the radii are now: one set for the scene when every type pair present
   has the same constants and each type one radius, one per type pair when
   each type has one radius, else from each pair's radii. The radii are
   checked when the neighbor list is built (atoms arrive, ghosts change),
   and at every step while a fix adapt, which changes them, is defined.
------------------------------------------------------------------------- */

PairJKRDT::ConstantsBy PairJKRDT::constants_by()
{
  if (!one_radius_per_type) return BY_RADII;
  if (!radii_adapt && radii_checked == neighbor->lastcall && !update->setupflag)
    return constants_source;
  radii_checked = neighbor->lastcall;
  const double *radius = atom->radius;
  const int *type = atom->type;
  const int nall = atom->nlocal + atom->nghost;
  constants_source = scene_pair >= 0 ? BY_SCENE : BY_TYPE;
  for (int k = 0; k < nall; k++)
    if (radius[k] != minrad[type[k]]) constants_source = BY_RADII;
  return constants_source;
}

/* ----------------------------------------------------------------------
   the pair loop over ilist entries [ii_from, ii_to), in five steps per
   pair: the distance test (all that a pair out of contact costs), the
   orientation and constants, the motion and its guards, contact_step(),
   and the loads and dissipation on this thread's owned atoms. TANGENTIAL:
   some type pair has a tangential channel. Most pairs in most steps are a
   contact that held between two atoms of this thread (LEAN, below): they
   take the same arithmetic on a short path out of line (lean_run(), or
   lean_put() and lean_deliver() around the lanes), which leaves the pair it
   cannot finish to the five steps.

   Orientation. The tangential state is kept for particle 1 = the smaller
   ID, so a contact with a channel is evaluated in that orientation, as
   follow_slots() stores it. The normal force needs no orientation: swapping
   the atoms negates d12 and v12 exactly and leaves every product the same,
   so without channels the pair is taken as the list gives it and the same
   bits result.
------------------------------------------------------------------------- */

template <bool TANGENTIAL, bool AVX2>
inline void PairJKRDT::pair_loop(int ii_from, int ii_to, int eflag, bool tally_atoms,
                                 ConstantsBy by, Accumulator &acc)
{
  using JKRDT::V3;
  // LAMMPS's per-atom 3-vectors are contiguous: index them flat, one load less per neighbor
  const double *const x = atom->x[0];
  const double *const v = atom->v[0];
  const double *const omega = atom->omega[0];
  const double *radius = atom->radius;
  const tagint *tag = atom->tag;
  const int *type = atom->type;
  const int *mask = atom->mask;
  const int departed = departed_bit;
  const int nlocal = atom->nlocal;
  const bool run_setup = update->setupflag;
  const double dt = update->dt;
  const double half_skin = 0.5 * neighbor->skin;
  double *const f = atom->f[0], *const tq = atom->torque[0];    // flat, as x
  double **ledger = fix_contacts->ledger;
  // an owned atom of another thread gets its share through acc.far
  const int *thread_of_atom = acc.thread_of;
  const int me = acc.thread;

  Contacts &C = *fix_contacts;
  const JKRDT::StateLayout layout = C.layout();
  unsigned char *const bonded_slot = C.bonded;
  double *const slot_values = C.slot_values;

  const JKRDT::ContactConstants *const scene_K =
      by == BY_SCENE ? &type_constants[scene_pair] : nullptr;
  JKRDT::ContactConstants cached{};    // BY_RADII: the last pair's, reused while they fit
  const Param *last_param = nullptr;
  double last_r1 = -1.0, last_r2 = -1.0;
  auto constants = [&](int p, int q) -> const JKRDT::ContactConstants & {
    if (by == BY_SCENE) return *scene_K;
    if (by == BY_TYPE) return type_constants[type[p] * nstride + type[q]];
    const Param &P = par(type[p], type[q]);
    if (&P != last_param || radius[p] != last_r1 || radius[q] != last_r2) {
      cached = JKRDT::contact_constants(P, radius[p], radius[q]);
      last_param = &P;
      last_r1 = radius[p];
      last_r2 = radius[q];
    }
    return cached;
  };
  // the sums of every step, in registers while the loop runs
  bigint contact_ends = 0;
  double step_max = acc.step_max;
  auto hand_over = [&]() {
    acc.contact_ends += contact_ends;
    acc.step_max = step_max;
  };
  auto trouble = [&](Trouble::Kind kind, int p, int q, double a, double b,
                     const JKRDT::ContactConstants &K) {
    if (tag[q] < tag[p]) std::swap(p, q);    // name the pair as the other rank does
    acc.trouble = {kind, p, q, a, b, K.S};
    hand_over();
  };
  // a pair of the block: where evaluate() leaves it for deliver()
  enum class Eval { SKIP, DONE, TROUBLE, LEAN };    // LEAN: lean_put() took it
  struct Done {
    int p, q, s, owned;
    bool parked, setup, formed;
    V3 d12;
    JKRDT::ContactMotion m;     // kept here: a lane reads it back (TangentialLanes::put)
    JKRDT::ContactResult out;
  };
  // the lanes' path: the tangential step four contacts at a time (jkr_dt_lanes.h), for
  // one set of constants and contacts that store their pointers
  const bool lanes = TANGENTIAL && by == BY_SCENE && scene_K->tangential && layout.pointers >= 0;

  // 1. the distance test, over a block of the list's pairs at a time: the pairs in
  // contact or touching are kept with their separation, and their r and 1/r are then
  // taken for the whole block at once: square roots and divisions that do not wait for
  // one another, instead of heading each pair's chain of dependent steps. 16 pairs: a
  // block's scratch (these arrays, the lanes' inputs, each contact's motion and result)
  // then stays in a 48 KB L1 cache between its passes; at 64 it did not, and the full
  // model's loop missed L1 on about 6 writes per pair (callgrind, docs/performance.md)
  constexpr int BLOCK = 16;
  struct {
    int i[BLOCK], j[BLOCK], slot[BLOCK];
    V3 d12[BLOCK];
    double rsq[BLOCK], radsum[BLOCK], r[BLOCK], rinv[BLOCK], y_near[BLOCK];
    Eval eval[BLOCK];
    Done done[BLOCK];
  } B;
  JKRDT::TangentialLanes<BLOCK> TL;

  // the common frictionless step (LEAN): a contact that held at the last step between two
  // atoms this thread owns, none departed, in a step that is no set-up and sums no energy
  // or virial. lean_run() takes a run [k0, k1) of such pairs of the block out of line, so
  // that the few values it needs stay in registers (inlined in the loop, the step shared
  // some 40 live values and reloaded them from the stack). It stops at a pair it cannot
  // finish (a guard, a contact that breaks: returns its k, nothing of it applied, for
  // evaluate() and deliver(), which give the same bits) and at a force that is not finite
  // (returns -(k + 1)); else it returns k1
  const bool lean_step = !run_setup && !tally_atoms && !eflag && !vflag_either;
  const bool lean_steps = !TANGENTIAL && lean_step;
  auto lean_run_body = [&](int k0, int k1) __attribute__((always_inline)) -> int {
    // the values the run reads, in locals: a store to a force may not alias them
    const double *const vv = v;
    double *const ff = f;
    double **const rows = ledger;
    const double step_dt = dt, skin_half = half_skin;
    const JKRDT::StateLayout L = layout;
    const JKRDT::ContactConstants *const K_scene = scene_K;    // else per pair (constants)
    double smax = step_max;
    bigint ends = 0;
    int k = k0;
    for (; k < k1; k++) {
      const int p = B.i[k], q = B.j[k];
      const JKRDT::ContactConstants &K = K_scene ? *K_scene : constants(p, q);
      const double r = B.r[k];
      const double delta = B.radsum[k] - r;    // eq. (3)
      if (!std::isfinite(delta) || r == 0.0 || delta < -K.S.delta_c) break;
      const V3 d12 = B.d12[k];
      const double rinv = B.rinv[k];
      const double vn = JKRDT::dot(JKRDT::vec(vv + 3 * p) - JKRDT::vec(vv + 3 * q), d12) * rinv;
      const double step = std::fabs(vn) * step_dt;
      if (step > skin_half) break;
      smax = std::max(smax, step * K.inv_delta_c);
      double *state = L.dnum ? slot_values + (bigint) B.slot[k] * L.dnum : nullptr;
      JKRDT::NormalResult nr;
      JKRDT::normal_step(K, L, vn, delta, step_dt, false, false, false, state, nr, B.y_near[k]);
      const V3 F1 = (nr.f * rinv) * d12;
      if (!std::isfinite(F1.x + F1.y + F1.z)) {
        step_max = smax;
        contact_ends += ends;
        return -(k + 1);
      }
      if (nr.lossy) {    // damped: F_D's work
        static_assert(JKRDT::LOSS_FORM_BREAK == 0 && JKRDT::LOSS_DAMPING == 1, "ledger order");
        const double loss[] = {nr.loss_event, nr.loss_damping};
        book_pair_losses(p, q, loss, 2, rows);
      }
      add_pair_force(p, q, F1, ff);
      ends += 2;
    }
    step_max = smax;
    contact_ends += ends;
    return k;
  };

  // with channels, on the lanes' path: lean_put() takes a run of such pairs to the lanes
  // (contact_normal_part, then TangentialLanes::put) and lean_deliver() adds their loads
  // after the lanes' step. lean_put() stops, nothing of the pair applied, at a pair that
  // needs a guard, breaks or has no pointers yet, and returns its k
  const bool lean_lanes = lanes && lean_step;
  auto lean_put_body = [&](int k0, int k1, int &nlane) __attribute__((always_inline)) -> int {
    const double *const vv = v, *const ww = omega;
    const double step_dt = dt, skin_half = half_skin;
    const JKRDT::StateLayout L = layout;
    const JKRDT::ContactConstants &K = *scene_K;
    double smax = step_max;
    int k = k0;
    for (; k < k1; k++) {
      const int p = B.i[k], q = B.j[k], s = B.slot[k];
      const double r = B.r[k];
      const double delta = B.radsum[k] - r;    // eq. (3)
      if (!std::isfinite(delta) || r == 0.0 || delta < -K.S.delta_c) break;
      double *state = slot_values + (bigint) s * L.dnum;
      if (!JKRDT::traced(state, L)) break;
      Done &o = B.done[k];
      JKRDT::ContactMotion &m = o.m;
      m.d12 = B.d12[k];
      m.r = r;
      m.rinv = B.rinv[k];
      m.v12 = JKRDT::vec(vv + 3 * p) - JKRDT::vec(vv + 3 * q);
      m.w1 = JKRDT::vec(ww + 3 * p);
      m.w2 = JKRDT::vec(ww + 3 * q);
      m.vn = JKRDT::dot(m.v12, m.d12) * m.rinv;
      const double step = std::fabs(m.vn) * step_dt;
      if (step > skin_half) break;
      smax = std::max(smax, step * K.inv_delta_c);
      JKRDT::contact_normal_part(K, L, m, delta, step_dt, false, false, false, state, o.out,
                                 B.y_near[k]);
      TL.put(nlane++, m, state, L, o.out);
      o.p = p;
      o.q = q;
      B.eval[k] = Eval::LEAN;
    }
    step_max = smax;
    return k;
  };
  // the loads of lean_put()'s pairs [k0, k1) as deliver() adds them; -(k + 1) where a force
  // is not finite, else k1
  auto lean_deliver_body = [&](int k0, int k1) __attribute__((always_inline)) -> int {
    double *const ff = f, *const tt = tq;
    double **const rows = ledger;
    bigint ends = 0;
    int k = k0;
    for (; k < k1; k++) {
      const Done &o = B.done[k];
      const int p = o.p, q = o.q;
      const JKRDT::ContactResult &out = o.out;
      const V3 F1 = out.F1;
      if (!std::isfinite(F1.x + F1.y + F1.z)) break;
      if (out.lossy) book_pair_losses(p, q, out.loss, JKRDT::NLOSS, rows);
      add_pair_force(p, q, F1, ff);
      add_pair_torques(p, q, out.M1, out.M2, tt);
      ends += 2;
    }
    contact_ends += ends;
    return k < k1 ? -(k + 1) : k1;
  };

  // each lean loop out of line, in the loop's own instructions (AVX2's three-operand forms
  // cut the frictionless loop's instructions 7 %, callgrind 2x2500)
  auto ool = [&](auto &run, auto &&...a) -> int {
#if JKRDT_AVX2
    if constexpr (AVX2) return out_of_line_avx2(run, std::forward<decltype(a)>(a)...);
#endif
    return out_of_line(run, std::forward<decltype(a)>(a)...);
  };
  auto lean_run = [&](int k0, int k1) { return ool(lean_run_body, k0, k1); };
  auto lean_put = [&](int k0, int k1, int &nlane) { return ool(lean_put_body, k0, k1, nlane); };
  auto lean_deliver = [&](int k0, int k1) { return ool(lean_deliver_body, k0, k1); };

  const SlotPair *const pairs = slot_pair.data();
  const int s_to = C.slot_first[ii_to];
  int s = C.slot_first[ii_from];
  while (s < s_to) {
    int n = 0;
    for (; s < s_to && n < BLOCK; s++) {
      const int i = pairs[s].p, j = pairs[s].q;
      const V3 d12 = JKRDT::vec(x + 3 * i) - JKRDT::vec(x + 3 * j);
      const double rsq = JKRDT::dot(d12, d12);
      const double radsum = by == BY_SCENE ? scene_K->radsum : radius[i] + radius[j];
      if (!bonded_slot[s] && rsq > radsum * radsum) continue;
      B.i[n] = i;
      B.j[n] = j;
      B.slot[n] = s;
      B.d12[n] = d12;
      B.rsq[n] = rsq;
      B.radsum[n] = radsum;
      n++;
    }
    for (int k = 0; k < n; k++) B.r[k] = std::sqrt(B.rsq[k]);
    for (int k = 0; k < n; k++) B.rinv[k] = 1.0 / B.r[k];
    // and, with one set of constants for the scene, the series root of eq. (4) that a
    // contact near rest takes (normal_step uses it only there)
    if (by == BY_SCENE) {
      const double inv_delta0 = scene_K->inv_delta0;
      for (int k = 0; k < n; k++)
        B.y_near[k] = JKRDT::contact_sqrt_radius_series((B.radsum[k] - B.r[k]) * inv_delta0 -
                                                        1.0);
    } else {
      std::fill(B.y_near, B.y_near + n, 0.0);
    }

    // 2.-4. each pair's contact over the step (evaluate); 5. its loads delivered (deliver).
    // On the lanes' path (below) the tangential step of the contacts on its common path
    // is taken four at a time in between, and every pair of the block is delivered after
    // it, in list order, as without it
    int nlane = 0;
    auto evaluate = [&](int k, Done &o) __attribute__((always_inline)) -> Eval {
      // 2. the pair as follow_slots() stored it (p = particle 1 where that matters) and its
      // constants
      const int p = B.i[k], q = B.j[k], s = B.slot[k];
      const bool bonded = bonded_slot[s];
      const V3 d12 = B.d12[k];
      const double radsum = B.radsum[k];
      const JKRDT::ContactConstants &K = constants(p, q);

      // a grain of a fragment that has left for good meets nothing, and its own contacts
      // stand still: they are only evaluated, as a set-up does, for their potential energy
      const int owned = (p < nlocal) + (q < nlocal);    // half per owned atom
      const bool parked = departed && ((mask[p] | mask[q]) & departed);
      if (parked && !(bonded && eflag)) {
        if (bonded) contact_ends += owned;
        return Eval::SKIP;
      }
      const bool setup = run_setup || parked;
      o.p = p;
      o.q = q;
      o.s = s;
      o.owned = owned;
      o.parked = parked;
      o.setup = setup;
      o.d12 = d12;

      // 3. the motion over the step, and the guards that name a pair the step cannot resolve
      const double r = B.r[k];
      const double delta = radsum - r;    // eq. (3)
      if (!std::isfinite(delta) || r == 0.0) {
        trouble(Trouble::BLOW_UP, p, q, r, 0.0, K);
        return Eval::TROUBLE;
      }
      JKRDT::ContactMotion &m = o.m;
      m.d12 = d12;
      m.r = r;
      m.rinv = B.rinv[k];
      m.v12 = JKRDT::vec(v + 3 * p) - JKRDT::vec(v + 3 * q);
      if (TANGENTIAL) {
        m.w1 = JKRDT::vec(omega + 3 * p);
        m.w2 = JKRDT::vec(omega + 3 * q);
      }
      m.vn = JKRDT::dot(m.v12, d12) * m.rinv;    // at the half step, > 0 when separating
      const double step = parked ? 0.0 : std::fabs(m.vn) * dt;
      if (step > half_skin) {
        trouble(Trouble::FAST_PAIR, p, q, m.vn, 0.0, K);
        return Eval::TROUBLE;
      }
      if (!setup) step_max = std::max(step_max, step * K.inv_delta_c);
      const bool formed = !bonded;    // delta >= 0 here: contact formation (section 2.1)
      o.formed = formed;
      if (formed && setup && delta >= std::min(radius[p], radius[q])) {
        trouble(Trouble::OVERLAP, p, q, delta, 0.0, K);
        return Eval::TROUBLE;
      }
      // a contact forms within the step that closes the gap: deeper means it was missed
      if (formed && !setup && delta > 2.0 * step + LATE_SLACK * K.S.delta_c) {
        trouble(Trouble::LATE, p, q, delta, step, K);
        return Eval::TROUBLE;
      }

      // 4. the contact over the step: the whole kernel, or its normal part alone, or (the
      // lanes' path) the normal part now and the tangential step in a lane
      double *state = layout.dnum ? slot_values + (bigint) s * layout.dnum : nullptr;
      JKRDT::ContactResult &out = o.out;
      if constexpr (!TANGENTIAL) {
        JKRDT::NormalResult nr;
        JKRDT::normal_step(K, layout, m.vn, delta, dt, setup, formed, eflag, state, nr,
                           B.y_near[k]);
        out.F1 = (nr.f * m.rinv) * d12;
        out.broken = nr.broken;
        out.lossy = nr.lossy;
        out.loss[JKRDT::LOSS_FORM_BREAK] = nr.loss_event;
        out.loss[JKRDT::LOSS_DAMPING] = nr.loss_damping;
        out.U_n = nr.U_n;
        return Eval::DONE;
      }
      // a lane takes a traced contact's step that is no set-up and does not break
      const bool in_lane = lanes && !setup && !formed && !(delta < -K.S.delta_c) &&
          JKRDT::traced(state, layout);
      if (!in_lane) {
        JKRDT::contact_step(K, layout, m, delta, dt, setup, formed, eflag, state, out,
                            B.y_near[k]);
        return Eval::DONE;
      }
      // contact_step()'s normal part now, its tangential step in a lane
      JKRDT::contact_normal_part(K, layout, m, delta, dt, false, false, eflag, state, out,
                                 B.y_near[k]);
      TL.put(nlane++, m, state, layout, out);
      return Eval::DONE;
    };

    auto deliver = [&](const Done &o) __attribute__((always_inline)) -> bool {
      const int p = o.p, q = o.q;
      const JKRDT::ContactResult &out = o.out;
      const V3 &fp = out.F1, &d12 = o.d12;
      const bool broken = out.broken, lossy = out.lossy;
      constexpr int nloss = TANGENTIAL ? JKRDT::NLOSS : JKRDT::LOSS_DAMPING + 1;
      if (!broken && !std::isfinite(fp.x + fp.y + fp.z)) {
        trouble(Trouble::NOT_FINITE, p, q, 0, 0, constants(p, q));
        return false;
      }
      bonded_slot[o.s] = !broken;

      // 5. force on p: normal (eq. 5 and A.5) plus sliding (eq. 14), -force on q; torques
      // eqs. (17), (23), (27); half of the step's dissipation to each owned atom
      if (!o.parked)
        for (int side = 0; side < 2; side++) {
          const int a = side ? q : p;
          if (a >= nlocal) continue;
          double *fa, *ta, *far_loss = nullptr;
          if (!thread_of_atom || thread_of_atom[a] == me) {
            fa = f + 3 * a;
            ta = tq + 3 * a;
          } else {
            acc.far.push_back(FarLoad{a, {0, 0, 0}, {0, 0, 0}, {}});
            fa = acc.far.back().f;
            ta = acc.far.back().torque;
            far_loss = acc.far.back().loss;
          }
          if (lossy && !o.setup) {    // the atom's ledger row only when it books
            double *la = far_loss ? far_loss : ledger[a];
            for (int l = 0; l < nloss; l++) la[l] += 0.5 * out.loss[l];
            // N_con, N_cut (3D BPCA paper, App. C.2): every formation and breaking books
            // a loss, and only here (the lean paths leave both to this step)
            if (o.formed) la[JKRDT::LEDGER_MADE] += 0.5;
            if (broken) la[JKRDT::LEDGER_CUT] += 0.5;
          }
          if (broken) continue;
          const V3 fa_add = side ? -fp : fp;
          fa[0] += fa_add.x;
          fa[1] += fa_add.y;
          fa[2] += fa_add.z;
          if (TANGENTIAL) {
            const V3 &ma = side ? out.M2 : out.M1;
            ta[0] += ma.x;
            ta[1] += ma.y;
            ta[2] += ma.z;
          }
        }
      if (broken) return true;

      // energy and virial
      contact_ends += o.owned;
      if (!eflag && !vflag_either) return true;
      const double share = 0.5 * o.owned;
      const double u = TANGENTIAL ? out.U_n + out.U[0] + out.U[1] + out.U[2] : out.U_n;
      if (eflag) {
        acc.upot += share * out.U_n;
        if (TANGENTIAL)
          for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) acc.utan[ch] += share * out.U[ch];
      }
      if (tally_atoms) {
        ev_tally_xyz(p, q, nlocal, 0, u, 0.0, fp.x, fp.y, fp.z, d12.x, d12.y, d12.z);
        return true;
      }
      // ev_tally_xyz with newton off, by hand: thread-safe into this thread's sums
      if (eflag_global) acc.eng += share * u;
      if (vflag_global) {
        acc.virial[0] += share * d12.x * fp.x;
        acc.virial[1] += share * d12.y * fp.y;
        acc.virial[2] += share * d12.z * fp.z;
        acc.virial[3] += share * d12.x * fp.y;
        acc.virial[4] += share * d12.x * fp.z;
        acc.virial[5] += share * d12.y * fp.z;
      }
      return true;
    };

    // a LEAN pair: bonded, both atoms this thread's (the list's atom i is; with channels the
    // pair may be stored the other way round), none departed
    auto lean = [&](int k) __attribute__((always_inline)) {
      const int i = B.i[k], j = B.j[k];
      if (!bonded_slot[B.slot[k]] || j >= nlocal || (TANGENTIAL && i >= nlocal) ||
          (departed && ((mask[i] | mask[j]) & departed)))
        return false;
      return !thread_of_atom ||
          (thread_of_atom[j] == me && (!TANGENTIAL || thread_of_atom[i] == me));
    };
    if constexpr (TANGENTIAL) {
      if (lanes) {
        for (int k = 0; k < n; k++) {
          if (lean_lanes && lean(k)) {
            int k1 = k + 1;
            while (k1 < n && lean(k1)) k1++;
            const int stop = lean_put(k, k1, nlane);
            if (stop == k1) {
              k = k1 - 1;
              continue;
            }
            k = stop;    // the pair lean_put() left, taken below
          }
          B.eval[k] = evaluate(k, B.done[k]);
          if (B.eval[k] == Eval::TROUBLE) return;
        }
        // 4b. the tangential step of the contacts on its common path, four at a time
        TL.step(nlane, *scene_K, layout, dt, eflag);
        for (int k = 0; k < n; k++) {
          if (B.eval[k] == Eval::LEAN) {
            int k1 = k + 1;
            while (k1 < n && B.eval[k1] == Eval::LEAN) k1++;
            const int stop = lean_deliver(k, k1);
            if (stop < 0) {
              trouble(Trouble::NOT_FINITE, B.done[-stop - 1].p, B.done[-stop - 1].q, 0, 0,
                      *scene_K);
              return;
            }
            k = k1 - 1;
            continue;
          }
          if (B.eval[k] == Eval::DONE && !deliver(B.done[k])) return;
        }
        continue;
      }
    }
    for (int k = 0; k < n; k++) {
      if (lean_steps && lean(k)) {
        int k1 = k + 1;
        while (k1 < n && lean(k1)) k1++;
        const int stop = lean_run(k, k1);
        if (stop < 0) {
          trouble(Trouble::NOT_FINITE, B.i[-stop - 1], B.j[-stop - 1], 0, 0,
                  constants(B.i[-stop - 1], B.j[-stop - 1]));
          return;
        }
        if (stop == k1) {
          k = k1 - 1;
          continue;
        }
        k = stop;    // the pair lean_run() left, taken below
      }
      Done o;
      const Eval e = evaluate(k, o);
      if (e == Eval::TROUBLE) return;
      if (e == Eval::DONE && !deliver(o)) return;
    }
  }
  hand_over();
}

/* ----------------------------------------------------------------------
   the loop compiled for any x86-64 and for AVX2: the same source, with the
   contact kernel's common path inlined (always_inline), so what differs is
   the instructions only. The AVX2 loop also inlines all else it can
   (flatten); the portable one does not, as SSE2 then spills more. What
   stays out of line (the rare clamped step's bookkeeping, libm) is
   portable code.
------------------------------------------------------------------------- */

template <bool TANGENTIAL>
void PairJKRDT::pair_loop_portable(int ii_from, int ii_to, int eflag, bool tally_atoms,
                                   ConstantsBy by, Accumulator &acc)
{
  pair_loop<TANGENTIAL, false>(ii_from, ii_to, eflag, tally_atoms, by, acc);
}

#if JKRDT_AVX2
template <bool TANGENTIAL>
__attribute__((target("avx2"), flatten)) void
PairJKRDT::pair_loop_avx2(int ii_from, int ii_to, int eflag, bool tally_atoms, ConstantsBy by,
                          Accumulator &acc)
{
  pair_loop<TANGENTIAL, true>(ii_from, ii_to, eflag, tally_atoms, by, acc);
}
#endif

/* ----------------------------------------------------------------------
   this rank's share of the 12 values of compute pair jkr/dt; compute pair
   sums them over ranks: the potentials, the losses, the bonded contacts,
   the contacts made and cut
------------------------------------------------------------------------- */

void PairJKRDT::fill_pvector(double upot, const double *utan, double contacts)
{
  std::fill(pvector, pvector + NPVECTOR, 0.0);
  pvector[0] = upot;    // U_n
  for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) pvector[1 + ch] = utan[ch];    // U_s, U_r, U_t
  const auto &C = *fix_contacts;
  for (int i = 0; i < atom->nlocal; i++) {
    for (int l = 0; l < Contacts::NLOSS; l++) pvector[4 + l] += C.ledger[i][l];
    pvector[10] += C.ledger[i][Contacts::MADE];
    pvector[11] += C.ledger[i][Contacts::CUT];
  }
  pvector[9] = contacts;
  for (int l = 0; l < NPVECTOR; l++)
    if (!std::isfinite(pvector[l]))
      error->one(FLERR,
                 "pair jkr/dt: value {} of the energy ledger is not finite at step {} (timestep "
                 "= {:.3g} t_c): the run has blown up; reduce the timestep",
                 l + 1, update->ntimestep, update->dt / tc_min);
}

