/* jkr/dt: what keeps a run honest. The time step against t_c, the neighbor
   settings contacts need, the input's overlaps, and the errors that name
   what went wrong when the integration cannot hold: a pair too fast for
   the step, a contact lost from the neighbor list, a non-finite number.

   t_c = sqrt(m delta_c / F_c), eq. (49) of Wada et al. (2007), is the time
   a contact takes to move by its own stretch delta_c at the speed v0 of
   eq. (48). It is taken for every type pair present from the smallest
   radius and the smallest mass of the two types, so that it is the
   shortest contact time of the system. The limits DT_WARN and DT_STABLE
   (pair_jkr_dt.h) are in units of it; how they were measured is in the
   manual page, "Choosing the time step".                                   */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <limits>

using namespace LAMMPS_NS;

/* ----------------------------------------------------------------------
   radius bounds and smallest mass of each type; radii must be > 0
------------------------------------------------------------------------- */

void PairJKRDT::find_max_radii()
{
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> big(nstride, 0.0), small(nstride, inf), light(nstride, inf);
  int bad = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    const double r = atom->radius[i];
    const double m = atom->rmass[i];
    const int t = atom->type[i];
    if (!(r > 0.0) || !std::isfinite(r) || !(m > 0.0) || !std::isfinite(m)) {
      bad = 1;
      continue;
    }
    big[t] = std::max(big[t], r);
    small[t] = std::min(small[t], r);
    light[t] = std::min(light[t], m);
  }
  int anybad = 0;
  MPI_Allreduce(&bad, &anybad, 1, MPI_INT, MPI_MAX, world);
  if (anybad)
    error->all(FLERR,
               "pair jkr/dt: every particle needs a finite radius > 0 and mass > 0 (set diameter, "
               "set density)");
  MPI_Allreduce(big.data(), maxrad.data(), nstride, MPI_DOUBLE, MPI_MAX, world);
  minrad.assign(nstride, inf);
  minmass.assign(nstride, inf);
  MPI_Allreduce(small.data(), minrad.data(), nstride, MPI_DOUBLE, MPI_MIN, world);
  MPI_Allreduce(light.data(), minmass.data(), nstride, MPI_DOUBLE, MPI_MIN, world);
}

/* ----------------------------------------------------------------------
   contacts form and break between two steps: the list must be current
   at every step, with a skin that a stretching contact cannot outrun
------------------------------------------------------------------------- */

void PairJKRDT::check_neighbor_settings() const
{
  if (neighbor->build_once)
    error->all(FLERR,
               "pair jkr/dt: neighbor lists are built once per run (neigh_modify once yes); "
               "contacts form and break between any two steps, so a stale list misses them. "
               "Use 'neigh_modify once no every 1 delay 0 check yes'");
  if (neighbor->every != 1 || neighbor->delay != 0)
    error->all(FLERR,
               "pair jkr/dt: neighbor lists checked every {} steps after a delay of {}; contacts "
               "form and break between any two steps, so a late list misses them. Use "
               "'neigh_modify every 1 delay 0 check yes'",
               neighbor->every, neighbor->delay);
  if (!(neighbor->skin > 0.0))
    error->all(FLERR,
               "pair jkr/dt: neighbor skin is {}; a stretched contact then leaves the list the "
               "step it should break. Set a skin of a few delta_c or more, e.g. 'neighbor 1.0e-8 "
               "bin' for 0.1 micron grains in SI units",
               neighbor->skin);
}

/* ----------------------------------------------------------------------
   velocity Verlet is what the energy ledger books against (the trapezoid
   of each load over a step); rRESPA splits the step and breaks that, and
   an integrator without rotation leaves the torques unused
------------------------------------------------------------------------- */

void PairJKRDT::check_integrator() const
{
  if (utils::strmatch(update->integrate_style, "^respa"))
    error->all(FLERR,
               "pair jkr/dt does not support run_style {}: the energy ledger books against one "
               "velocity-Verlet step. Use 'run_style verlet' with 'fix nve/sphere'",
               update->integrate_style);
  bool integrated = false, rotates = false;
  for (const auto *fix : modify->get_fix_list()) {
    if (!fix->time_integrate) continue;
    integrated = true;
    if (utils::strmatch(fix->style, "sphere") || utils::strmatch(fix->style, "^rigid"))
      rotates = true;
  }
  if (integrated && !rotates && comm->me == 0)
    error->warning(FLERR,
                   "pair jkr/dt: no time-integration fix turns the grains (fix nve/sphere): the "
                   "sliding, rolling and twisting torques act on frozen spins. Use 'fix ID all "
                   "nve/sphere'");
}

/* ----------------------------------------------------------------------
   t_c of the type pairs present: the smallest, and its types
------------------------------------------------------------------------- */

void PairJKRDT::find_contact_time()
{
  tc_min = std::numeric_limits<double>::infinity();
  tc_types[0] = tc_types[1] = 0;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (!std::isfinite(minrad[i]) || !std::isfinite(minrad[j])) continue;    // type absent
      const Param &P = par(i, j);
      const auto S = JKRDT::normal_scales(minrad[i], minrad[j], P.gamma, P.a0_coef);
      const double tc = std::sqrt(std::min(minmass[i], minmass[j]) * S.delta_c / S.F_c);
      if (tc < tc_min) {
        tc_min = tc;
        tc_types[0] = i;
        tc_types[1] = j;
      }
    }
}

/* ----------------------------------------------------------------------
   E_break of the weakest contact present: U_n of eq. (6) at the break point
   y_break (delta = -delta_c) above its equilibrium value at y = 1
------------------------------------------------------------------------- */

double PairJKRDT::weakest_contact(double &lightest) const
{
  double weakest = std::numeric_limits<double>::infinity();
  lightest = std::numeric_limits<double>::infinity();
  const double ratio = JKRDT::potential_ratio_at_break() - JKRDT::normal_potential_ratio(1.0);
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (!std::isfinite(minrad[i]) || !std::isfinite(minrad[j])) continue;    // type absent
      const Param &P = par(i, j);
      const auto S = JKRDT::normal_scales(minrad[i], minrad[j], P.gamma, P.a0_coef);
      weakest = std::min(weakest, ratio * S.F_c * S.delta_c);
      lightest = std::min({lightest, minmass[i], minmass[j]});
    }
  return weakest;
}

/* ----------------------------------------------------------------------
   once per run (at its set-up, or at its first step for 'run N pre no',
   which has no set-up): dt / t_c to the log, and the limits for a run with steps
------------------------------------------------------------------------- */

void PairJKRDT::check_time_step()
{
  if (!std::isfinite(tc_min)) return;    // no atoms yet
  const int ti = tc_types[0], tj = tc_types[1];
  const double dt = update->dt;
  const double ratio = dt / tc_min;
  if (comm->me == 0 && (tc_min != tc_logged || dt != dt_logged))
    utils::logmesg(lmp,
                   "pair jkr/dt: t_c = {:.6g} (types {} {}, eq. 49 of Wada et al. 2007); "
                   "timestep {:.6g} = {:.4g} t_c\n",
                   tc_min, ti, tj, dt, ratio);
  tc_logged = tc_min;
  dt_logged = dt;
  if (update->whichflag != 1 || update->nsteps == 0) return;    // a run that integrates
  if (ratio > DT_STABLE) {
    const std::string what = fmt::format(
        "pair jkr/dt: timestep {:.4g} is {:.3g} t_c (t_c = {:.4g}, types {} {}): above {} t_c "
        "velocity Verlet cannot hold a contact and the energy runs away. Use timestep <= {:.4g} "
        "({} t_c; 0.014 t_c keeps the energy error near 1e-4), or 'pair_style jkr/dt dt_check "
        "warn' to run anyway",
        dt, ratio, tc_min, ti, tj, DT_STABLE, DT_STABLE * tc_min, DT_STABLE);
    if (dt_check == DT_CHECK_ERROR) error->all(FLERR, what);
    if (dt_check == DT_CHECK_WARN && comm->me == 0 && dt != dt_warned) error->warning(FLERR, what);
  } else if (ratio > DT_WARN && dt_check != DT_CHECK_OFF && comm->me == 0 && dt != dt_warned) {
    error->warning(FLERR,
                   "pair jkr/dt: timestep {:.4g} is {:.3g} t_c, above {} t_c: expect energy errors "
                   "of 1e-3 and more (see 'Choosing the time step' in the manual)",
                   dt, ratio, DT_WARN);
  }
  dt_warned = dt;    // one warning per time step, not one per run of a chunked session
}

/* ----------------------------------------------------------------------
   a contact found when a run starts deeper than the smaller radius:
   overlapping input is named as such
------------------------------------------------------------------------- */

void PairJKRDT::report_overlap(int p, int q, double delta, const JKRDT::NormalScales &S) const
{
  const double rmin = std::min(atom->radius[p], atom->radius[q]);
  error->one(FLERR,
             "pair jkr/dt: atoms {} and {} overlap by {:.4g} ({:.3g} of the smaller radius) "
             "in the input: one sits inside the other. Overlapping input: move them apart "
             "(the builders place bonded grains at r1 + r2 - delta0, delta0 = {:.4g})",
             atom->tag[p], atom->tag[q], delta, delta / rmin, S.delta0);
}

/* ----------------------------------------------------------------------
   the problem a thread of the pair loop met, named
------------------------------------------------------------------------- */

void PairJKRDT::report(const Trouble &t) const
{
  switch (t.kind) {
    case Trouble::BLOW_UP: report_blow_up(t.p, t.q, t.a);
    case Trouble::FAST_PAIR: report_fast_pair(t.p, t.q, t.a);
    case Trouble::OVERLAP: report_overlap(t.p, t.q, t.a, t.S);
    case Trouble::LATE: report_late_contact(t.p, t.q, t.a, t.b, t.S);
    case Trouble::NOT_FINITE: report_not_finite(t.p, t.q, "force");
    default: error->one(FLERR, "pair jkr/dt: unknown trouble (internal error)");
  }
}

/* ---------------------------------------------------------------------- */

void PairJKRDT::report_blow_up(int p, int q, double r) const
{
  if (update->setupflag && r == 0.0)
    error->one(FLERR,
               "pair jkr/dt: atoms {} and {} are at the same position in the input (distance "
               "0): overlapping input; remove one of them or move them apart",
               atom->tag[p], atom->tag[q]);
  error->one(FLERR,
             "pair jkr/dt: atoms {} and {} are at distance {} at step {}: the run has blown up "
             "at timestep {:.4g} = {:.3g} t_c. Reduce the timestep (0.014 t_c is the papers' "
             "choice)",
             atom->tag[p], atom->tag[q], r, update->ntimestep, update->dt, update->dt / tc_min);
}

void PairJKRDT::report_not_finite(int p, int q, const char *what) const
{
  error->one(FLERR,
             "pair jkr/dt: the {} of the contact between atoms {} and {} is not finite at step "
             "{} (timestep {:.4g} = {:.3g} t_c): the run has blown up; reduce the timestep",
             what, atom->tag[p], atom->tag[q], update->ntimestep, update->dt,
             update->dt / tc_min);
}

/* ----------------------------------------------------------------------
   a pair whose normal motion in one step exceeds half the skin: the list
   can no longer be trusted to hold it, so stop before a contact is lost
------------------------------------------------------------------------- */

void PairJKRDT::report_fast_pair(int p, int q, double vn) const
{
  const double move = std::fabs(vn) * update->dt;
  error->one(FLERR,
             "pair jkr/dt: atoms {} and {} move {:.4g} relative to each other in one step "
             "(|v_n| = {:.4g} times timestep {:.4g} = {:.3g} t_c), more than half the neighbor "
             "skin {:.4g}: contacts would be missed or lost. Reduce the timestep below {:.4g} or "
             "raise the skin above {:.4g}",
             atom->tag[p], atom->tag[q], move, std::fabs(vn), update->dt, update->dt / tc_min,
             neighbor->skin, 0.5 * neighbor->skin / std::fabs(vn), 2.0 * move);
}

/* ----------------------------------------------------------------------
   a contact first seen deeper than the pair moved in the step: the list
   missed its formation, or something other than the integration moved
   the atoms during the run
------------------------------------------------------------------------- */

void PairJKRDT::report_late_contact(int p, int q, double delta, double step,
                                    const JKRDT::NormalScales &S) const
{
  error->one(FLERR,
             "pair jkr/dt: the contact between atoms {} and {} is first seen at step {} "
             "already overlapped by {:.4g} ({:.3g} delta_c), more than the {:.4g} they moved "
             "towards each other in the step: it was missed when it formed. Either the "
             "neighbor list did not hold the pair (neigh_modify exclude, a list not rebuilt) "
             "or the atoms were moved by something other than the integration (a fix that "
             "moves atoms, or positions changed between 'run N pre no' chunks). Move atoms "
             "only before a run that does its set-up ('run N', pre yes)",
             atom->tag[p], atom->tag[q], update->ntimestep, delta, delta / S.delta_c, step);
}

/* ----------------------------------------------------------------------
   a stored contact that the new neighbor list does not hold: say why and stop
------------------------------------------------------------------------- */

void PairJKRDT::contact_lost()
{
  const int nlocal = atom->nlocal;
  const tagint *tag = atom->tag;
  std::vector<std::vector<tagint>> seen(nlocal);
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      if (i < nlocal) seen[i].push_back(tag[j]);
      if (j < nlocal) seen[j].push_back(tag[i]);
    }
  }
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < fix_contacts->npartner[i]; k++) {
      const tagint t = fix_contacts->partner[i][k];
      if (std::find(seen[i].begin(), seen[i].end(), t) != seen[i].end()) continue;
      const int j = (atom->map_style != Atom::MAP_NONE) ? atom->map(t) : -1;
      if (j < 0)
        error->one(FLERR,
                   "pair jkr/dt: atom {} has a contact with atom {}, which is no longer within "
                   "reach: it was deleted, or it flew out of this rank's ghost region in one "
                   "step (timestep {:.4g} = {:.3g} t_c). Delete atoms only together with their "
                   "contact partners, or reduce the timestep",
                   tag[i], t, update->dt, update->dt / tc_min);
      double **x = atom->x, **v = atom->v;
      const double d[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double w[3] = {v[i][0] - v[j][0], v[i][1] - v[j][1], v[i][2] - v[j][2]};
      const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double vrel = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      const double move = vrel * update->dt;
      const double gap = r - atom->radius[i] - atom->radius[j];
      if (move < neighbor->skin)
        error->one(FLERR,
                   "pair jkr/dt: the contact between atoms {} and {} left the neighbor list "
                   "before it could break: they are {:.4g} apart ({:.4g} beyond r1 + r2), but "
                   "their relative speed moves them only {:.4g} per step: they were moved by "
                   "something other than the integration (set, displace_atoms, change_box, a "
                   "fix that moves atoms), or neigh_modify exclude took the pair out of the "
                   "list. Move bonded grains together, or delete the contacts' "
                   "atoms first",
                   tag[i], t, r, gap, move);
      error->one(FLERR,
                 "pair jkr/dt: the contact between atoms {} and {} left the neighbor list "
                 "before it could break: they are {:.4g} apart ({:.4g} beyond r1 + r2) and move "
                 "at {:.4g} relative to each other, {:.4g} per step (timestep {:.4g} = {:.3g} "
                 "t_c) against a skin of {:.4g}. A contact must stretch by less than the skin "
                 "in one step: reduce the timestep below {:.4g} or raise the skin above {:.4g}",
                 tag[i], t, r, gap, vrel, move, update->dt,
                 update->dt / tc_min, neighbor->skin, 0.5 * neighbor->skin / vrel, 2.0 * move);
    }
  error->one(FLERR, "pair jkr/dt: contact bookkeeping is inconsistent on this rank");
}

/* ----------------------------------------------------------------------
   end of a run: warn once if a contact moved by more than STEP_WARN delta_c
   in one step. event_loss() books what the integrator did, so the budget
   closes, but the loss of one event is then off by O(F_c |v_n| dt / 2)
------------------------------------------------------------------------- */

void PairJKRDT::run_ended()
{
  double most = 0.0;
  MPI_Allreduce(&step_max, &most, 1, MPI_DOUBLE, MPI_MAX, world);
  step_max = 0.0;
  contacts_at_run_end = fix_contacts->count();
  fix_contacts->natoms_at_run_end = atom->natoms;
  if (step_warned || most <= STEP_WARN) return;
  step_warned = true;
  if (comm->me == 0)
    error->warning(FLERR,
                   "pair jkr/dt: a contact moved {:.3g} delta_c along its normal in one step "
                   "(timestep {:.4g} = {:.3g} t_c), more than {} delta_c: contacts form and "
                   "break up to that far from where they should, so each such event books a "
                   "loss off by up to about {:.2g} F_c delta_c (the jumps of U_n are 0.85 and "
                   "0.09 F_c delta_c). The energy budget still closes; reduce the timestep for "
                   "accurate event losses",
                   most, update->dt, update->dt / tc_min, STEP_WARN, 0.5 * most);
}

/* ----------------------------------------------------------------------
   a data file cannot carry contacts (pointers, twist, damping force, the
   ledger): write_data marks the file with the count of bonded contacts it
   leaves behind (keyword data_contacts), and a run read from it is refused
------------------------------------------------------------------------- */

void PairJKRDT::check_data_file_contacts() const
{
  if (data_contacts > 0)
    error->all(FLERR,
               "pair jkr/dt: this data file was written by write_data from a state with {} "
               "bonded contacts, which a data file cannot carry (pointers, twist, damping force, "
               "energy ledger): the run would start with them all broken. Continue from "
               "write_restart / read_restart instead; to start from the positions alone, give "
               "'pair_style jkr/dt' again after read_data, then pair_coeff",
               data_contacts);
}

/* ----------------------------------------------------------------------
   the dt_check setting travels with restart files
------------------------------------------------------------------------- */

void PairJKRDT::write_restart_settings(FILE *fp)
{
  fwrite(&dt_check, sizeof(int), 1, fp);
}

void PairJKRDT::read_restart_settings(FILE *fp)
{
  if (comm->me == 0) utils::sfread(FLERR, &dt_check, sizeof(int), 1, fp, nullptr, error);
  MPI_Bcast(&dt_check, 1, MPI_INT, 0, world);
}
