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
#include "jkr_dt_normal.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;
using Contacts = FixJKRDTContacts;

const char *const PairJKRDT::FIX_ID = "JKR_DT_CONTACTS";

/* ---------------------------------------------------------------------- */

PairJKRDT::PairJKRDT(LAMMPS *lmp) :
    Pair(lmp), fix_contacts(nullptr), nstride(0),
    dt_check(DT_CHECK_ERROR), tc_min(0.0), tc_types{0, 0}, tc_logged(0.0), dt_logged(0.0),
    dt_warned(0.0), checked_laststep(-1), step_max(0.0),
    step_warned(false), contacts_at_run_end(0), data_contacts(0)
{
  single_enable = 0;
  restartinfo = 1;
  writedata = 1;
  no_virial_fdotr_compute = 1;    // forces go to owned atoms only
  nextra = NPVECTOR;
  pvector = new double[nextra];
  std::fill(pvector, pvector + nextra, 0.0);
}

/* ---------------------------------------------------------------------- */

PairJKRDT::~PairJKRDT()
{
  delete[] pvector;
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
  }
  // the contact fix outlives the pair style: a pair_style command that replaces jkr/dt
  // leaves the contacts in place, and the fix refuses a run without jkr/dt while it
  // holds any (FixJKRDTContacts::init); pair_style jkr/dt given again takes them back
}

/* ---------------------------------------------------------------------- */

void PairJKRDT::init_style()
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

  neighbor->add_request(this, NeighConst::REQ_NEWTON_OFF);

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
    fix_contacts->set_layout(layout_mask());
  } else {
    fix_contacts = dynamic_cast<Contacts *>(
        modify->add_fix(fmt::format("{} all jkr/dt/contacts {}", FIX_ID, layout_mask())));
  }
}

/* ----------------------------------------------------------------------
   per-contact fields that some type pair needs
------------------------------------------------------------------------- */

int PairJKRDT::layout_mask() const
{
  int mask = 0;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      const Param &P = par(i, j);
      if (P.damp_coef > 0.0) mask |= 1 << Contacts::DAMPING_FORCE;
      if (P.sliding || P.rolling) mask |= 1 << Contacts::POINTERS;
      if (P.twisting) mask |= 1 << Contacts::TWIST;
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

/* ----------------------------------------------------------------------
   half of a contact's dissipation goes to each of its owned atoms
------------------------------------------------------------------------- */

void PairJKRDT::book(const double loss[JKRDT::NLOSS], int p, int q, int nlocal)
{
  for (int l = 0; l < JKRDT::NLOSS; l++) {
    if (loss[l] == 0.0) continue;
    if (p < nlocal) fix_contacts->ledger[p][l] += 0.5 * loss[l];
    if (q < nlocal) fix_contacts->ledger[q][l] += 0.5 * loss[l];
  }
}

/* ---------------------------------------------------------------------- */

void PairJKRDT::compute(int eflag, int vflag)
{
  using JKRDT::V3;
  ev_init(eflag, vflag);

  double **x = atom->x;
  double **v = atom->v;
  double **omega = atom->omega;
  double **f = atom->f;
  double **torque = atom->torque;
  const double *radius = atom->radius;
  const tagint *tag = atom->tag;
  const int *type = atom->type;
  const int nlocal = atom->nlocal;
  const bool setup = update->setupflag;
  const double dt = update->dt;
  const double half_skin = 0.5 * neighbor->skin;

  if (update->laststep != checked_laststep) {    // once per run, 'run N pre no' included
    checked_laststep = update->laststep;
    check_time_step();
  }

  Contacts &C = *fix_contacts;
  if (!C.slots_follow(list)) C.to_slots(list);    // a list built without post_neighbor
  const JKRDT::StateLayout layout = C.layout();
  unsigned char *const bonded_slot = C.bonded;
  double *const slot_values = C.slot_values;

  // the constants depend on the type pair and the radii only: reuse the last ones
  JKRDT::ContactConstants K{};
  const Param *last_param = nullptr;
  double last_r1 = -1.0, last_r2 = -1.0;
  double upot = 0.0, contacts = 0.0;
  double utan[JKRDT::NCHANNEL] = {0.0, 0.0, 0.0};
  JKRDT::ContactResult out;
  const int inum = list->inum;
  const int *ilist = list->ilist;
  const int *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;

  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    const int *jlist = firstneigh[i];
    int s = C.slot_first[ii];
    for (int jj = 0; jj < numneigh[i]; jj++, s++) {
      const int j = jlist[jj] & NEIGHMASK;

      // canonical orientation: p has the smaller ID
      int p = i, q = j;
      if (tag[q] < tag[p]) std::swap(p, q);
      const bool bonded = bonded_slot[s];

      const V3 d12 = {x[p][0] - x[q][0], x[p][1] - x[q][1], x[p][2] - x[q][2]};
      const double rsq = JKRDT::dot(d12, d12);
      const double radsum = radius[p] + radius[q];
      if (!bonded && rsq > radsum * radsum) continue;

      const double r = std::sqrt(rsq);
      const double delta = radsum - r;    // eq. (3)
      if (!std::isfinite(delta) || r == 0.0) report_blow_up(p, q, r);

      const Param &P = par(type[p], type[q]);
      if (&P != last_param || radius[p] != last_r1 || radius[q] != last_r2) {
        K = JKRDT::contact_constants(P, radius[p], radius[q]);
        last_param = &P;
        last_r1 = radius[p];
        last_r2 = radius[q];
      }

      JKRDT::ContactMotion m;
      m.d12 = d12;
      m.r = r;
      m.v12 = JKRDT::vec(v[p]) - JKRDT::vec(v[q]);
      m.w1 = JKRDT::vec(omega[p]);
      m.w2 = JKRDT::vec(omega[q]);
      m.vn = JKRDT::dot(m.v12, d12) / r;    // at the half step, > 0 when separating

      // a step must resolve the contact: name a pair too fast for the list
      const double step = std::fabs(m.vn) * dt;
      if (step > half_skin) report_fast_pair(p, q, m.vn);
      if (!setup) step_max = std::max(step_max, step / K.S.delta_c);

      const bool formed = !bonded;    // delta >= 0 here: contact formation (section 2.1)
      if (formed && setup) check_initial_overlap(p, q, delta, K.S);
      // a contact forms within the step that closes the gap: deeper means it was missed
      if (formed && !setup && delta > 2.0 * step + LATE_SLACK * K.S.delta_c)
        report_late_contact(p, q, delta, step, K.S);

      double *state = layout.dnum ? slot_values + (bigint) s * layout.dnum : nullptr;
      JKRDT::contact_step(K, layout, m, delta, dt, setup, formed, eflag, state, out);
      if (!setup) book(out.loss, p, q, nlocal);
      if (out.broken) {
        bonded_slot[s] = 0;
        continue;
      }
      bonded_slot[s] = 1;

      // force on p: normal (eq. 5 and A.5) plus sliding (eq. 14); torques eqs. (17), (23), (27)
      const V3 &fp = out.F1;
      if (!std::isfinite(fp.x + fp.y + fp.z)) report_not_finite(p, q, "force");
      const bool p_own = p < nlocal, q_own = q < nlocal;
      if (p_own) {
        f[p][0] += fp.x;
        f[p][1] += fp.y;
        f[p][2] += fp.z;
        torque[p][0] += out.M1.x;
        torque[p][1] += out.M1.y;
        torque[p][2] += out.M1.z;
      }
      if (q_own) {
        f[q][0] -= fp.x;
        f[q][1] -= fp.y;
        f[q][2] -= fp.z;
        torque[q][0] += out.M2.x;
        torque[q][1] += out.M2.y;
        torque[q][2] += out.M2.z;
      }
      const double share = 0.5 * ((p_own ? 1.0 : 0.0) + (q_own ? 1.0 : 0.0));
      contacts += share;
      if (eflag) {
        upot += share * out.U_n;
        for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) utan[ch] += share * out.U[ch];
      }
      if (evflag)
        ev_tally_xyz(p, q, nlocal, 0, out.U_n + out.U[0] + out.U[1] + out.U[2], 0.0, fp.x, fp.y,
                     fp.z, d12.x, d12.y, d12.z);
    }
  }

  C.rows_changed();
  if (eflag_global) fill_pvector(upot, utan, contacts);
}

/* ----------------------------------------------------------------------
   this rank's share of the 10 values of compute pair jkr/dt; compute pair
   sums them over ranks
------------------------------------------------------------------------- */

void PairJKRDT::fill_pvector(double upot, const double *utan, double contacts)
{
  std::fill(pvector, pvector + NPVECTOR, 0.0);
  pvector[0] = upot;    // U_n
  for (int ch = 0; ch < JKRDT::NCHANNEL; ch++) pvector[1 + ch] = utan[ch];    // U_s, U_r, U_t
  const auto &C = *fix_contacts;
  for (int i = 0; i < atom->nlocal; i++)
    for (int l = 0; l < Contacts::NLEDGER; l++) pvector[4 + l] += C.ledger[i][l];
  pvector[9] = contacts;
  for (int l = 0; l < NPVECTOR; l++)
    if (!std::isfinite(pvector[l]))
      error->one(FLERR,
                 "pair jkr/dt: value {} of the energy ledger is not finite at step {} (timestep "
                 "= {:.3g} t_c): the run has blown up; reduce the timestep",
                 l + 1, update->ntimestep, update->dt / tc_min);
}

FixJKRDTContacts *PairJKRDT::contacts()
{
  if (fix_contacts) fix_contacts->to_rows();
  return fix_contacts;
}

/* ----------------------------------------------------------------------
   quantities of the bonded contact between local atom i and atom j
------------------------------------------------------------------------- */

bool PairJKRDT::bonded_contact(int i, int j, ContactView &view) const
{
  const tagint *tag = atom->tag;
  const int k = fix_contacts->find(i, tag[j]);
  if (k < 0) return false;
  int p = i, q = j;
  if (tag[q] < tag[p]) std::swap(p, q);
  double **x = atom->x;
  const double dx = x[p][0] - x[q][0], dy = x[p][1] - x[q][1], dz = x[p][2] - x[q][2];
  const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
  const Param &P = par(atom->type[p], atom->type[q]);
  const auto K = JKRDT::contact_constants(P, atom->radius[p], atom->radius[q]);
  const auto &S = K.S;
  view.id1 = tag[p];
  view.id2 = tag[q];
  view.delta = atom->radius[p] + atom->radius[q] - r;
  const double y = JKRDT::contact_sqrt_radius(view.delta / S.delta0);
  view.a = y * y * S.a0;
  view.force = S.F_c * JKRDT::normal_force_ratio(y);
  const auto &C = *fix_contacts;
  if (P.damp_coef > 0.0) view.force -= C.contact_values(i, k)[C.offset(Contacts::DAMPING_FORCE)];
  view.zeta = view.xi = view.phi = 0.0;
  JKRDT::ContactState c;
  if (P.tangential() && JKRDT::load_state(C.contact_values(i, k), C.layout(), c)) {
    const JKRDT::V3 nc = JKRDT::unit({dx, dy, dz});
    if (P.sliding)
      view.zeta = JKRDT::norm(JKRDT::tangential_part(
          JKRDT::sliding_zeta0(c, nc, atom->radius[p], atom->radius[q]), nc));
    if (P.rolling) view.xi = JKRDT::norm(JKRDT::rolling_xi(c, S.R));
    if (P.twisting) view.phi = std::fabs(c.phi);
  }
  return true;
}

/* ---------------------------------------------------------------------- */

double PairJKRDT::memory_usage()
{
  return Pair::memory_usage() +
      (input.size() * sizeof(Input) + param.size() * sizeof(Param));
}
