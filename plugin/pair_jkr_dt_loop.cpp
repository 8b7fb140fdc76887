/* jkr/dt: the neighbor-list loop over one step: threads, blocks of pairs,
   the LEAN runs, the sums and compute pair jkr/dt's values. One pair's step
   (its motion, guards, contact kernel, loads and ledger) is written once, in
   pair_jkr_dt_step.h.

   Parallel layout. The style asks for a half neighbor list built as with
   newton off, whatever the global newton setting: a pair with one ghost atom
   is computed on both ranks, and each rank writes forces and contact state
   only for its own atoms. The contact state is kept in list order, one copy
   per pair of this rank's list (FixJKRDTContacts): a pair with a ghost atom
   is kept, and advanced identically, on both ranks, so no reverse
   communication of contact state is ever needed. Each pair is
   evaluated in its canonical orientation (particle 1 = smaller atom ID), so
   the two ranks do the same arithmetic on the same numbers.                */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"
#include "pair_jkr_dt_step.h"

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
   the pair loop over ilist entries [ii_from, ii_to): a block of the list's
   pairs at a time, each pair in the steps of pair_jkr_dt_step.h. Most pairs
   in most steps are a contact that held between two atoms of this thread:
   runs of them take the LEAN step out of line (lean_run, or lean_put and
   lean_deliver around the lanes), which leaves a pair it cannot finish to
   the general step.

   Orientation. The tangential state is kept for particle 1 = the smaller
   ID, so a contact with a channel is evaluated in that orientation, as
   follow_slots() stores it. The normal force needs no orientation: swapping
   the atoms negates d12 and v12 exactly and leaves every product the same,
   so without channels the pair is taken as the list gives it and the same
   bits result.
------------------------------------------------------------------------- */

PairJKRDT::View PairJKRDT::view(int eflag, bool tally_atoms, ConstantsBy by,
                                const Accumulator &acc) const
{
  View w;
  w.x = atom->x[0];
  w.v = atom->v[0];
  w.omega = atom->omega[0];
  w.radius = atom->radius;
  w.tag = atom->tag;
  w.type = atom->type;
  w.mask = atom->mask;
  w.f = atom->f[0];
  w.torque = atom->torque[0];
  w.ledger = fix_contacts->ledger;
  w.bonded = fix_contacts->bonded;
  w.slot_values = fix_contacts->slot_values;
  w.layout = fix_contacts->layout();
  w.thread_of = acc.thread_of;
  w.me = acc.thread;
  w.nlocal = atom->nlocal;
  w.departed = departed_bit;
  w.eflag = eflag;
  w.setup = update->setupflag;
  w.tally_atoms = tally_atoms;
  w.eflag_global = eflag_global;
  w.vflag_global = vflag_global;
  w.vflag_either = vflag_either;
  w.dt = update->dt;
  w.half_skin = 0.5 * neighbor->skin;
  w.scene_K = by == BY_SCENE ? &type_constants[scene_pair] : nullptr;
  w.lanes = any_tangential && w.scene_K && w.scene_K->tangential && w.layout.pointers >= 0;
  return w;
}

// one thread's pass over its range of the list
template <bool TANGENTIAL, bool AVX2> struct PairJKRDT::Pass {
  const View w;
  Constants by_pair;
  Block<TANGENTIAL> B;
  Accumulator &acc;
  PairJKRDT &pair;
  PairStep<TANGENTIAL, false> general;
  bool lean_steps, lean_lanes;    // runs of pairs take the LEAN step

  Pass(PairJKRDT &style, const View &view, ConstantsBy by, Accumulator &a) :
      w(view), by_pair{style, by, view.radius, view.type}, acc(a), pair(style),
      general(w, by_pair, B, a, style)
  {
    const bool lean = style.lean_enabled && !w.setup && !w.tally_atoms && !w.eflag &&
        !w.vflag_either;
    lean_steps = !TANGENTIAL && lean;
    lean_lanes = TANGENTIAL && w.lanes && lean;
  }

  void run(int s, int s_to)
  {
    const SlotPair *const pairs = pair.slot_pair.data();
    while (s < s_to) {
      const int n = B.fill(pairs, s, s_to, w);
      if (!(TANGENTIAL && w.lanes ? lanes_block(n) : plain_block(n))) break;
    }
    general.hand_over();
  }

  // the end of a run of pairs that may take the LEAN step, from k
  int lean_end(int k, int n) const
  {
    while (k < n && B.lean(k, w)) k++;
    return k;
  }

  // each pair of the block evaluated and delivered in turn; false: trouble
  bool plain_block(int n)
  {
    for (int k = 0; k < n; k++) {
      if constexpr (!TANGENTIAL) {
        if (lean_steps && B.lean(k, w)) {
          const int k1 = lean_end(k + 1, n);
          const int stop = lean_run(k, k1);
          if (stop < 0) return false;
          if (stop == k1) {
            k = k1 - 1;
            continue;
          }
          k = stop;    // the pair the LEAN step left, taken below
        }
      }
      Done o;
      const Eval e = general.evaluate(k, o);
      if (e == Eval::TROUBLE) return false;
      if (e == Eval::DONE && !general.deliver(o)) return false;
    }
    return true;
  }

  // the lanes' path: every pair evaluated, the tangential step of the contacts on its
  // common path taken four at a time, then every pair delivered in list order, as
  // without the lanes
  bool lanes_block(int n)
  {
    B.nlane = 0;
    for (int k = 0; k < n; k++) {
      if (lean_lanes && B.lean(k, w)) {
        const int k1 = lean_end(k + 1, n);
        const int stop = lean_put(k, k1);
        if (stop == k1) {
          k = k1 - 1;
          continue;
        }
        k = stop;    // the pair the LEAN step left, taken below
      }
      B.eval[k] = general.evaluate(k, B.done[k]);
      if (B.eval[k] == Eval::TROUBLE) return false;
    }
    B.lanes.step(B.nlane, *w.scene_K, w.layout, w.dt, w.eflag);
    for (int k = 0; k < n; k++) {
      if (B.eval[k] == Eval::LEAN) {
        int k1 = k + 1;
        while (k1 < n && B.eval[k1] == Eval::LEAN) k1++;
        if (lean_deliver(k, k1) < 0) return false;
        k = k1 - 1;
        continue;
      }
      if (B.eval[k] == Eval::DONE && !general.deliver(B.done[k])) return false;
    }
    return true;
  }

  // the LEAN step of pairs [k0, k1), out of line, in the loop's own instructions (AVX2's
  // three-operand forms cut the frictionless loop's instructions 7 %, callgrind 2x2500):
  // returns the first pair it left, or -1 where a force was not finite
  template <class Steps> int out_of_line(Steps &steps, int k0, int k1)
  {
#if JKRDT_AVX2
    if constexpr (AVX2) return lean_avx2(steps, k0, k1);
#endif
    return lean_sse2(steps, k0, k1);
  }
  // evaluated and delivered (without channels)
  int lean_run(int k0, int k1)
  {
    auto steps = [this](PairStep<TANGENTIAL, true> &st, int k) __attribute__((always_inline)) {
      Done o;
      if (st.evaluate(k, o) == Eval::STOP) return 0;
      return st.deliver(o) ? 1 : -1;
    };
    return out_of_line(steps, k0, k1);
  }
  // evaluated and put in the lanes (with channels) ...
  int lean_put(int k0, int k1)
  {
    auto steps = [this](PairStep<TANGENTIAL, true> &st, int k) __attribute__((always_inline)) {
      if (st.evaluate(k, B.done[k]) == Eval::STOP) return 0;
      B.eval[k] = Eval::LEAN;
      return 1;
    };
    return out_of_line(steps, k0, k1);
  }
  // ... and delivered after the lanes' step
  int lean_deliver(int k0, int k1)
  {
    auto steps = [this](PairStep<TANGENTIAL, true> &st, int k) __attribute__((always_inline)) {
      return st.deliver(B.done[k]) ? 1 : -1;
    };
    return out_of_line(steps, k0, k1);
  }

  // one step per pair from k0 until one stops (0) or fails (-1)
  template <class Steps> [[gnu::always_inline]] int lean(Steps &steps, int k0, int k1)
  {
    PairStep<TANGENTIAL, true> st(w, by_pair, B, acc, pair);
    int k = k0;
    for (; k < k1; k++) {
      const int done = steps(st, k);
      if (done <= 0) {
        if (done < 0) k = -1;
        break;
      }
    }
    st.hand_over();
    return k;
  }
  template <class Steps> [[gnu::noinline]] int lean_sse2(Steps &steps, int k0, int k1)
  {
    return lean(steps, k0, k1);
  }
#if JKRDT_AVX2
  template <class Steps>
  [[gnu::noinline, gnu::target("avx2")]] int lean_avx2(Steps &steps, int k0, int k1)
  {
    return lean(steps, k0, k1);
  }
#endif
};

template <bool TANGENTIAL, bool AVX2>
inline void PairJKRDT::pair_loop(int ii_from, int ii_to, int eflag, bool tally_atoms,
                                 ConstantsBy by, Accumulator &acc)
{
  Pass<TANGENTIAL, AVX2> pass(*this, view(eflag, tally_atoms, by, acc), by, acc);
  pass.run(fix_contacts->slot_first[ii_from], fix_contacts->slot_first[ii_to]);
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
   this rank's share of the values of compute pair jkr/dt (JKRDT::PairValue);
   compute pair sums them over ranks: the potentials, the losses, the bonded
   contacts, the contacts made and cut
------------------------------------------------------------------------- */

void PairJKRDT::fill_pvector(double upot, const double *utan, double contacts)
{
  using namespace JKRDT;
  std::fill(pvector, pvector + NPVECTOR, 0.0);
  pvector[VALUE_U_N] = upot;
  for (int ch = 0; ch < NCHANNEL; ch++) pvector[VALUE_U_TANGENTIAL + ch] = utan[ch];
  const auto &C = *fix_contacts;
  for (int i = 0; i < atom->nlocal; i++) {
    for (int l = 0; l < NLOSS; l++) pvector[VALUE_LOSS + l] += C.ledger[i][l];
    pvector[VALUE_MADE] += C.ledger[i][LEDGER_MADE];
    pvector[VALUE_CUT] += C.ledger[i][LEDGER_CUT];
  }
  pvector[VALUE_CONTACTS] = contacts;
  for (int l = 0; l < NPVECTOR; l++)
    if (!std::isfinite(pvector[l]))
      error->one(FLERR,
                 "pair jkr/dt: value {} ({}) of the energy ledger is not finite at step {} "
                 "(timestep = {:.3g} t_c): the run has blown up; reduce the timestep",
                 l + 1, VALUE_NAME[l], update->ntimestep, update->dt / tc_min);
}
