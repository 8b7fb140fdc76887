/* jkr/dt: the settle rule. See fix_jkr_dt_settle.h. */

#include "fix_jkr_dt_settle.h"

#include "fix_jkr_dt_contacts.h"
#include "pair_jkr_dt.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "modify.h"
#include "timer.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <vector>

using namespace LAMMPS_NS;

// the simulated time as LAMMPS counts it (atime from the last change of dt or restart)
static double lammps_time(const Update *update)
{
  return update->atime + (update->ntimestep - update->atimestep) * update->dt;
}

/* ---------------------------------------------------------------------- */

FixJKRDTSettle::FixJKRDTSettle(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), window(5), tolerance(0.01), counts(1.0e-4), stretch(0.0), cap(-1.0),
    state(RUNNING), rerun(false), last_check(-1),
    now{0, 0, 0, 0.0, 0.0}, largest(-1), departure(lmp),
    time_origin(lammps_time(update)),
    dt_origin(update->dt), step_origin(update->ntimestep), table_append(false)
{
  const char *usage = "fix ID all jkr/dt/settle N window K tolerance f [counts c] "
                      "[stretch s] [cap T] [depart yes|no|shadow] [table FILE] [append yes|no]";
  if (narg < 4) error->all(FLERR, "fix jkr/dt/settle: expected '{}'", usage);
  if (igroup != 0)
    error->all(FLERR, "fix jkr/dt/settle: the fragments are those of all atoms; use group all");
  nevery = utils::inumeric(FLERR, arg[3], false, lmp);
  if (nevery < 1) error->all(FLERR, "fix jkr/dt/settle: N (steps between checks) must be >= 1");
  for (int iarg = 4; iarg < narg; iarg += 2) {
    const std::string key = arg[iarg];
    if (iarg + 1 >= narg) error->all(FLERR, "fix jkr/dt/settle: {} needs a value", key);
    if (key == "window") {
      window = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (window < 1) error->all(FLERR, "fix jkr/dt/settle: window must be >= 1 check");
    } else if (key == "tolerance") {
      tolerance = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(tolerance >= 0.0 && tolerance < 1.0))
        error->all(FLERR, "fix jkr/dt/settle: tolerance is a fraction in [0, 1) (got {})",
                   tolerance);
    } else if (key == "counts") {
      counts = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(counts >= 0.0 && counts < 1.0))
        error->all(FLERR, "fix jkr/dt/settle: counts is a fraction of all grains in [0, 1) "
                   "(got {}; 0 asks N_lar and the fragment count to stay unchanged)", counts);
    } else if (key == "stretch") {
      stretch = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(stretch >= 0.0 && stretch <= 1.0))
        error->all(FLERR, "fix jkr/dt/settle: stretch is a fraction of all grains in [0, 1] "
                   "(got {}; 0 does not watch shape, 0.25 watches a largest fragment of a "
                   "quarter of the grains or more)", stretch);
    } else if (key == "cap") {
      cap = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(cap > 0.0)) error->all(FLERR, "fix jkr/dt/settle: cap is a simulated time > 0");
    } else if (key == "depart") {
      const std::string how = arg[iarg + 1];
      if (how == "yes") departure.mode = SettleDeparture::YES;
      else if (how == "no") departure.mode = SettleDeparture::NO;
      else if (how == "shadow") departure.mode = SettleDeparture::SHADOW;
      else error->all(FLERR, "fix jkr/dt/settle: depart is yes, no or shadow (got '{}')", how);
    } else if (key == "table") {
      table_path = arg[iarg + 1];
    } else if (key == "append") {
      table_append = utils::logical(FLERR, arg[iarg + 1], false, lmp) == 1;
    } else {
      error->all(FLERR, "fix jkr/dt/settle: unknown keyword '{}'; expected '{}'", key, usage);
    }
  }
  if (cap > 0.0) cap += simulated_time();    // the cap counts from the fix's definition
  if (!table_path.empty()) table.reset(new SettleTable(lmp, table_path, table_append));
  restart_global = 1;
  vector_flag = 1;
  size_vector = 8;
  global_freq = 1;
  extvector = 0;
}

FixJKRDTSettle::~FixJKRDTSettle()
{
}

int FixJKRDTSettle::setmask()
{
  return FixConst::END_OF_STEP;
}

void FixJKRDTSettle::post_constructor()
{
  // the group exists before the pair style's init looks for it
  if (departure.mode == SettleDeparture::YES) {
    departure.departed_bit = group->bitmask[group->find_or_create(PairJKRDT::DEPARTED_GROUP)];
    force_reneighbor = 1;    // a departure reaches the ghost atoms' masks at the next step
    next_reneighbor = -1;
  }
}

void FixJKRDTSettle::init()
{
  auto *pair = PairJKRDT::active(lmp);
  if (!pair) error->all(FLERR, "fix jkr/dt/settle requires pair_style jkr/dt");
  if (departure.mode == SettleDeparture::NO) return;
  double lightest;
  departure.break_energy = pair->weakest_contact(lightest);
  departure.quiet_speed = std::sqrt(departure.break_energy / lightest);
  if (departure.mode != SettleDeparture::YES) return;
  departure.moving_bits = 0;
  for (const auto *fix : modify->get_fix_list()) {
    if (!fix->time_integrate) continue;
    if (fix->igroup == 0)
      error->all(FLERR,
                 "fix jkr/dt/settle depart yes: fix {} integrates group all, so departed "
                 "fragments would keep moving; integrate a group of its own instead "
                 "('group moving subtract all {}' and 'fix {} moving {}')",
                 fix->id, PairJKRDT::DEPARTED_GROUP, fix->id, fix->style);
    departure.moving_bits |= fix->groupbit;
  }
}

void FixJKRDTSettle::setup(int)
{
  // every run is watched anew, its window continuing the checks of earlier runs (a
  // run in chunks), unless the step count went back (reset_timestep, a restart)
  state = RUNNING;
  rerun = false;
  if (update->ntimestep < last_check) history.clear();
  if (history.empty()) {
    Graph graph;
    now = partition(graph);
    last_check = update->ntimestep;
    history.push_back(now);
    write_check(graph);
  }
}

/* ----------------------------------------------------------------------
   fragments of the whole system: union-find over the bonded contacts of
   all ranks, each contact taken once (from the atom with the smaller ID)
------------------------------------------------------------------------- */

FixJKRDTSettle::Partition FixJKRDTSettle::partition(Graph &graph)
{
  auto *pair = PairJKRDT::active(lmp);
  const FixJKRDTContacts *C = pair ? pair->contacts() : nullptr;
  std::vector<tagint> mine;
  if (C)
    for (int i = 0; i < atom->nlocal; i++)
      for (int k = 0; k < C->npartner[i]; k++)
        if (atom->tag[i] < C->partner[i][k]) {
          mine.push_back(atom->tag[i]);
          mine.push_back(C->partner[i][k]);
        }
  double dissipated = 0.0;
  if (C)
    for (int i = 0; i < atom->nlocal; i++)
      for (int l = 0; l < JKRDT::NLOSS; l++) dissipated += C->ledger[i][l];
  graph.edges = FixJKRDTContacts::gather(mine, world);
  const std::vector<tagint> &edges = graph.edges;

  // union by size over the atoms that have contacts; the others are single grains
  auto &index = graph.index;
  auto &parent = graph.parent;
  auto &size = graph.size;
  auto node = [&](tagint t) {
    auto it = index.find(t);
    if (it != index.end()) return it->second;
    const int k = static_cast<int>(parent.size());
    index.emplace(t, k);
    parent.push_back(k);
    size.push_back(1);
    return k;
  };
  auto root = [&](int k) { return graph.root(k); };
  bigint unions = 0;
  for (size_t e = 0; e < edges.size(); e += 2) {
    int a = root(node(edges[e])), b = root(node(edges[e + 1]));
    if (a == b) continue;
    if (size[a] < size[b]) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
    unions++;
  }
  Partition p;
  p.n_largest = size.empty() ? (atom->natoms > 0 ? 1 : 0) : *std::max_element(size.begin(), size.end());
  p.n_fragments = atom->natoms - unions;
  p.contacts = static_cast<bigint>(edges.size() / 2);
  MPI_Allreduce(&dissipated, &p.dissipated, 1, MPI_DOUBLE, MPI_SUM, world);
  largest = graph.largest();
  p.gyration_radius = gyration_radius(graph, largest);
  return p;
}

/* ----------------------------------------------------------------------
   r_g of the fragment of root k (equal grains), eq. (50) of Wada et al.
   (2007): about the box centre, then shifted to the fragment's; 0 for none
------------------------------------------------------------------------- */

double FixJKRDTSettle::gyration_radius(Graph &graph, int k) const
{
  double centre[3], local[5] = {0, 0, 0, 0, 0}, total[5];
  for (int d = 0; d < 3; d++) centre[d] = 0.5 * (domain->boxlo[d] + domain->boxhi[d]);
  double **x = atom->x;
  for (int i = 0; k >= 0 && i < atom->nlocal; i++) {
    auto it = graph.index.find(atom->tag[i]);
    if (it == graph.index.end() || graph.root(it->second) != k) continue;
    local[0] += 1.0;
    for (int d = 0; d < 3; d++) {
      const double dx = x[i][d] - centre[d];
      local[1 + d] += dx;
      local[4] += dx * dx;
    }
  }
  MPI_Allreduce(local, total, 5, MPI_DOUBLE, MPI_SUM, world);
  if (!(total[0] > 0.0)) return 0.0;
  double mean2 = 0.0;
  for (int d = 0; d < 3; d++) mean2 += (total[1 + d] / total[0]) * (total[1 + d] / total[0]);
  return std::sqrt(std::max(0.0, total[4] / total[0] - mean2));
}

void FixJKRDTSettle::write_check(Graph &graph)
{
  if (table)
    table->write(graph, {simulated_time(), now.n_fragments, now.contacts,
                         departure.departed_grains, departure.departed_fragments, largest,
                         now.gyration_radius});
}

double FixJKRDTSettle::simulated_time() const
{
  if (update->dt != dt_origin) return lammps_time(update);
  return time_origin + (update->ntimestep - step_origin) * dt_origin;
}

/* ---------------------------------------------------------------------- */

void FixJKRDTSettle::end_of_step()
{
  if (state != RUNNING) return;
  Graph graph;
  now = partition(graph);
  last_check = update->ntimestep;
  history.push_back(now);
  while (static_cast<int>(history.size()) > window + 1) history.pop_front();

  int reason = RUNNING;
  if (static_cast<int>(history.size()) == window + 1) {
    // each count's range over the window
    bigint lo[3] = {now.n_largest, now.n_fragments, now.contacts};
    bigint hi[3] = {now.n_largest, now.n_fragments, now.contacts};
    for (const auto &h : history) {
      const bigint of[3] = {h.n_largest, h.n_fragments, h.contacts};
      for (int k = 0; k < 3; k++) {
        lo[k] = std::min(lo[k], of[k]);
        hi[k] = std::max(hi[k], of[k]);
      }
    }
    const bigint allowed = static_cast<bigint>(std::floor(counts * atom->natoms));
    const bool same = hi[0] - lo[0] <= allowed && hi[1] - lo[1] <= allowed;
    const double dissipating = now.dissipated - history.front().dissipated;
    if (same && (hi[2] - lo[2]) <= tolerance * hi[2] &&
        dissipating <= tolerance * std::fabs(now.dissipated) && !stretched())
      reason = SETTLED;
  }
  // the cap is met when the next check would lie beyond it
  if (reason == RUNNING && cap > 0.0 && simulated_time() + 0.5 * nevery * update->dt > cap)
    reason = CAP;
  if (reason == RUNNING && departure.mode != SettleDeparture::NO) {
    const FixJKRDTContacts *C = PairJKRDT::active(lmp)->contacts();
    if (departure.find(graph, C->npartner, simulated_time()))
      next_reneighbor = update->ntimestep + 1;
  }
  write_check(graph);
  if (reason != RUNNING) {
    stop(reason);
  } else if (PairJKRDT::active(lmp)->bins_outgrown()) {
    rerun = true;
    if (comm->me == 0)
      utils::logmesg(lmp, "jkr/dt/settle: new run for wider bins step {}\n", update->ntimestep);
    timer->force_timeout();
  }
}

/* ----------------------------------------------------------------------
   stretch s: a largest fragment of at least s of all grains whose r_g grew
   by more than f over the window is a body still being pulled apart (a neck
   without rolling or sliding resistance stretches at constant N_lar and
   contacts, dissipating nothing, and may part later): not settled. Where
   the window's first r_g is unknown (< 0: a window read from a restart file
   of an older build, which kept none), the rule waits for a window it knows.
------------------------------------------------------------------------- */

bool FixJKRDTSettle::stretched() const
{
  if (!(stretch > 0.0) ||
      static_cast<double>(now.n_largest) < stretch * static_cast<double>(atom->natoms))
    return false;
  const double before = history.front().gyration_radius;
  if (before < 0.0) return true;
  return before > 0.0 && now.gyration_radius / before - 1.0 > tolerance;
}

void FixJKRDTSettle::stop(int reason)
{
  state = reason;
  if (comm->me == 0)
    utils::logmesg(lmp,
                   "jkr/dt/settle: stop_reason {} step {} time {:.10g} N_lar {} fragments {} "
                   "contacts {}\n",
                   reason == SETTLED ? "settled" : "cap", update->ntimestep, simulated_time(),
                   now.n_largest, now.n_fragments, now.contacts);
  timer->force_timeout();
}

void FixJKRDTSettle::post_run()
{
  timer->reset_timeout();    // later commands and runs are not cut short
}

double FixJKRDTSettle::compute_vector(int n)
{
  switch (n) {
    case 0: return state;
    case 1: return static_cast<double>(now.n_largest);
    case 2: return static_cast<double>(now.n_fragments);
    case 3: return static_cast<double>(now.contacts);
    case 4: return static_cast<double>(last_check);
    case 5: return departure.departed_grains;
    case 6: return departure.departed_fragments;
    default: return rerun ? 1.0 : 0.0;
  }
}

/* ----------------------------------------------------------------------
   restart: the last check and the window's partitions, after a header: a marker
   (RESTART_WALL, not a whole number, where older files hold the last check's step),
   the table's wall clock, so that a continued run's wall column goes on from it, and
   the origin of the simulated time (time, step, dt)
------------------------------------------------------------------------- */

static constexpr double RESTART_WALL = -2.5;    // never a step (older files: -1 or a step)
// the same header, each check of the window with its largest fragment's r_g as well
static constexpr double RESTART_SHAPE = -3.5;

void FixJKRDTSettle::write_restart(FILE *fp)
{
  std::vector<double> list = {RESTART_SHAPE, table ? table->wall() : 0.0, time_origin,
                              static_cast<double>(step_origin), dt_origin,
                              static_cast<double>(last_check),
                              static_cast<double>(history.size())};
  for (const auto &h : history) {
    list.push_back(static_cast<double>(h.n_largest));
    list.push_back(static_cast<double>(h.n_fragments));
    list.push_back(static_cast<double>(h.contacts));
    list.push_back(h.dissipated);
    list.push_back(h.gyration_radius);
  }
  if (comm->me == 0) {
    int size = static_cast<int>(list.size() * sizeof(double));
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list.data(), sizeof(double), list.size(), fp);
  }
}

void FixJKRDTSettle::restart(char *buf)
{
  auto *list = reinterpret_cast<double *>(buf);
  const int per = list[0] == RESTART_SHAPE ? 5 : 4;    // older files: no r_g (-1, unknown)
  if (list[0] == RESTART_WALL || list[0] == RESTART_SHAPE) {    // older: the last check
    if (table) table->continue_from(list[1]);
    time_origin = list[2];
    step_origin = static_cast<bigint>(list[3]);
    dt_origin = list[4];
    list += 5;
  }
  last_check = static_cast<bigint>(list[0]);
  const int n = static_cast<int>(list[1]);
  history.clear();
  for (int k = 0; k < n; k++) {
    const double *p = list + 2 + per * k;
    history.push_back({static_cast<bigint>(p[0]), static_cast<bigint>(p[1]),
                       static_cast<bigint>(p[2]), p[3], per == 5 ? p[4] : -1.0});
  }
  if (!history.empty()) now = history.back();
}
