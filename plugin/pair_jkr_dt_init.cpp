/* jkr/dt: pair_style jkr/dt set up for a run (init_style): what it needs
   of the atoms and the deck, the coefficients of every type pair and the
   constants of their contacts, and the contact store it writes, with the
   hooks that store calls back.                                              */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;
using Contacts = FixJKRDTContacts;

/* ---------------------------------------------------------------------- */

void PairJKRDT::init_style()
{
  check_atom_style();
  find_max_radii();
  double cutmax = 0.0;
  std::vector<Param> fresh(param.size());
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fresh[i * nstride + j] = fresh[j * nstride + i] = resolve(i, j);
      cutmax = std::max(cutmax, fresh[i * nstride + j].cut);
    }
  // stored contacts, whether this pair style made them or takes them over from one that
  // a pair_style command replaced: deleted partners go, renumbering is refused, and a
  // channel switched off since the last run hands its springs' energy to its ledger
  // with the constants the springs were made with
  auto *held = dynamic_cast<Contacts *>(modify->get_fix_by_id(FIX_ID));
  if (held) {
    fix_contacts = held;
    held->check_atoms(held->natoms_at_run_end);
    book_channels_switched_off(fresh, *held);
  }
  param = fresh;
  check_periodic_images(cutmax);
  check_neighbor_settings();
  check_integrator();
  check_data_file_contacts();
  find_contact_time();
  find_contact_constants();

  const int departed = group->find(DEPARTED_GROUP);
  departed_bit = departed >= 0 ? group->bitmask[departed] : 0;

  neighbor->add_request(this, NeighConst::REQ_NEWTON_OFF);
  start_bins(cutmax + neighbor->skin);
  choose_kernel();
  attach_contact_store();
}

/* ----------------------------------------------------------------------
   what the pair needs of the atoms and the run
------------------------------------------------------------------------- */

void PairJKRDT::check_atom_style() const
{
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag)
    error->all(FLERR,
               "pair jkr/dt requires atom_style sphere (per-atom radius, rmass and omega)");
  if (!comm->ghost_velocity)
    error->all(FLERR,
               "pair jkr/dt requires velocities of ghost atoms: add 'comm_modify vel yes'");
  if (!atom->tag_enable)
    error->all(FLERR, "pair jkr/dt requires atom IDs: contacts are keyed by the IDs of the pair");
  if (!atom->torque_flag)
    error->all(FLERR, "pair jkr/dt requires per-atom torque: use atom_style sphere");
  if (update->whichflag == 2)
    error->all(FLERR,
               "pair jkr/dt cannot be minimized: its contacts carry history (pointers, twist, "
               "breaking). Relax with a damped run instead (e.g. fix viscous)");
}

/* ----------------------------------------------------------------------
   the constants of the contacts of every type pair present, and where the
   pair loop finds them (constants_by): whether each type has one radius,
   and whether one set serves the whole scene
------------------------------------------------------------------------- */

void PairJKRDT::find_contact_constants()
{
  one_radius_per_type = true;
  any_tangential = false;
  type_constants.assign(param.size(), JKRDT::ContactConstants{});
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = 1; j <= atom->ntypes; j++) {
      const bool present = std::isfinite(minrad[i]) && std::isfinite(minrad[j]);
      if (present && (minrad[i] != maxrad[i] || minrad[j] != maxrad[j]))
        one_radius_per_type = false;
      if (present)
        type_constants[i * nstride + j] = JKRDT::contact_constants(par(i, j), minrad[i], minrad[j]);
      any_tangential = any_tangential || par(i, j).tangential();
    }
  radii_adapt = false;
  for (const Fix *fix : modify->get_fix_list())
    radii_adapt = radii_adapt || utils::strmatch(fix->style, "^adapt");
  radii_checked = -1;
  // one set of constants for the scene: every type pair present has the same numbers
  // (the usual two aggregates of one material, given two types)
  scene_pair = -1;
  for (int i = 1; i <= atom->ntypes && one_radius_per_type; i++)
    for (int j = 1; j <= atom->ntypes; j++) {
      if (!std::isfinite(minrad[i]) || !std::isfinite(minrad[j])) continue;
      if (scene_pair < 0) scene_pair = i * nstride + j;
      if (!JKRDT::same_constants(type_constants[i * nstride + j], type_constants[scene_pair])) {
        scene_pair = -1;
        i = atom->ntypes;
        break;
      }
    }
}

/* ----------------------------------------------------------------------
   the AVX2 loop where this CPU has AVX2 (kernel auto): the same bits,
   fewer instructions; the log says which loop and how many threads
------------------------------------------------------------------------- */

void PairJKRDT::choose_kernel()
{
#if JKRDT_AVX2
  kernel_avx2 = kernel_auto && __builtin_cpu_supports("avx2");
#else
  kernel_avx2 = false;
#endif
  const int nthreads = nthreads_used();
  if (comm->me == 0 &&
      (nthreads != threads_logged || kernel_avx2 != kernel_logged || lean_enabled != lean_logged))
    utils::logmesg(lmp, "pair jkr/dt: {} OpenMP thread{} per rank, {} pair loop{}\n", nthreads,
                   nthreads > 1 ? "s" : "", kernel_avx2 ? "AVX2" : "portable",
                   lean_enabled ? "" : ", every pair on the general step (lean no)");
  threads_logged = nthreads;
  kernel_logged = kernel_avx2;
  lean_logged = lean_enabled;
#if !defined(_OPENMP)
  if (comm->me == 0 && comm->nthreads > 1)
    error->warning(FLERR, "pair jkr/dt was built without OpenMP: it runs on 1 thread of the {} "
                          "asked for; rebuild with an OpenMP compiler", comm->nthreads);
#endif
}

/* ----------------------------------------------------------------------
   the contact store this pair writes: found, or made (with the contacts a
   restart file brought back), told the state's layout, what the contacts
   are made with, and the hooks it calls back
------------------------------------------------------------------------- */

void PairJKRDT::attach_contact_store()
{
  auto *fix = modify->get_fix_by_id(FIX_ID);
  if (!fix && fix_contacts && contacts_at_run_end > 0)
    error->all(FLERR,
               "pair jkr/dt: its contact fix {} was removed (unfix) with the {} bonded contacts "
               "it held; the run would start with them all broken. Do not unfix {}; to start "
               "from the positions alone, give 'pair_style jkr/dt' and 'pair_coeff' anew",
               FIX_ID, contacts_at_run_end, FIX_ID);
  if (fix) {
    fix_contacts = dynamic_cast<Contacts *>(fix);
    if (!fix_contacts) error->all(FLERR, "fix ID {} is reserved for pair jkr/dt", FIX_ID);
  } else {
    // contacts read from a restart file come back in the new fix with what they were made
    // with, so a channel switched off since is booked as between two runs
    fix_contacts = dynamic_cast<Contacts *>(
        modify->add_fix(fmt::format("{} all jkr/dt/contacts {}", FIX_ID, layout_mask())));
    book_channels_switched_off(param, *fix_contacts);
  }
  fix_contacts->set_layout(layout_mask());
  fix_contacts->made_with = made_with_record(param);
  fix_contacts->writer.by = this;
  fix_contacts->writer.list_of_slots = [this]() -> const NeighList * { return list; };
  fix_contacts->writer.on_exchange = [this]() { fit_bins(neighbor->cutneighmax); };
  fix_contacts->writer.on_run_end = [this]() { run_ended(); };
  fix_contacts->writer.on_lost_contact = [this]() { contact_lost(); };
}

/* ----------------------------------------------------------------------
   per-contact fields that some type pair needs
------------------------------------------------------------------------- */

int PairJKRDT::layout_mask() const
{
  int mask = 0;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      mask |= JKRDT::state_fields(par(i, j));
    }
  return mask;
}

/* ----------------------------------------------------------------------
   contact state is looked up by partner ID, so a particle must never see
   two periodic images of one partner inside its neighbor list
------------------------------------------------------------------------- */

void PairJKRDT::check_periodic_images(double cutmax)
{
  const double need = 2.0 * (cutmax + neighbor->skin);
  const char *axis = "xyz";
  for (int d = 0; d < domain->dimension; d++)
    if (domain->periodicity[d] && domain->prd[d] < need)
      error->all(FLERR,
                 "pair jkr/dt: periodic box length {} along {} is shorter than 2 (cutoff + skin) "
                 "= {}; a particle could see two images of one contact partner. Enlarge the box "
                 "or make that direction non-periodic",
                 domain->prd[d], axis[d], need);
}

