/* jkr/dt: the pair style's own state: construction, the look-up of the
   style and of its contact store, the bonded contacts as the local compute
   reports them, memory. The rest of the class, each part above this one:
     pair_jkr_dt_init.cpp      init_style: checks, constants, the contact store
     pair_jkr_dt_loop.cpp      compute: the neighbor-list loop and the ledger
     pair_jkr_dt_coeff.cpp     pair_coeff, data and restart files
     pair_jkr_dt_guards.cpp    t_c and the time-step limits, errors of a run
     pair_jkr_dt_bins.cpp      bins that grow with the box
     pair_jkr_dt_tangential.cpp  a tangential channel switched off between runs
   None of them is called from here.                                          */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;
using Contacts = FixJKRDTContacts;

const char *const PairJKRDT::FIX_ID = "JKR_DT_CONTACTS";
const char *const PairJKRDT::DEPARTED_GROUP = "jkrdt_departed";

/* ---------------------------------------------------------------------- */

PairJKRDT::PairJKRDT(LAMMPS *lmp) :
    Pair(lmp), fix_contacts(nullptr), departed_bit(0), bins_bounded(true), kernel_auto(true),
    kernel_avx2(false), bin_size_set(0.0), bin_size_logged(0.0), bin_size_run(0.0),
    bins_stale(false), threads_logged(0), nstride(0),
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
  // looked up, not remembered: the fix may be gone already (unfix, or plugins unloaded)
  auto *held = modify ? dynamic_cast<Contacts *>(modify->get_fix_by_id(FIX_ID)) : nullptr;
  if (held && held->writer.by == this) held->writer = Contacts::Writer();
  delete[] pvector;
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
  }
  // the contact fix outlives the pair style: a pair_style command that replaces jkr/dt
  // leaves the contacts in place (with no writer), and the fix refuses a run without
  // jkr/dt while it holds any (FixJKRDTContacts::init); pair_style jkr/dt given again
  // takes them back
}

/* ----------------------------------------------------------------------
   threads: comm->nthreads (OMP_NUM_THREADS, package omp N, -sf omp). The
   neighbor list's atoms are cut into one contiguous range per thread, so a
   contact's slot belongs to one thread; forces, torques and the ledger of
   threads 1.. go to buffers summed into the atoms' arrays in thread order.
   Per-atom energy or virial tallies run on one thread.
------------------------------------------------------------------------- */

int PairJKRDT::nthreads_used() const
{
#if defined(_OPENMP)
  return std::max(1, comm->nthreads);
#else
  return 1;
#endif
}

PairJKRDT *PairJKRDT::active(LAMMPS *lmp)
{
  return dynamic_cast<PairJKRDT *>(lmp->force->pair_match("jkr/dt", 1, 0));
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
  if (P.damp_coef > 0.0) view.force -= C.contact_values(i, k)[C.layout().fd];
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
      (input.size() * sizeof(Input) + param.size() * sizeof(Param) +
       slot_pair.capacity() * sizeof(SlotPair));
}
