/* jkr/dt: contact output. See compute_jkr_dt.h. */

#include "compute_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"
#include "pair_jkr_dt.h"

#include "atom.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "neigh_list.h"
#include "update.h"

#include <utility>

using namespace LAMMPS_NS;

static PairJKRDT *find_pair(LAMMPS *lmp, const char *style)
{
  auto *pair = PairJKRDT::active(lmp);
  if (!pair) lmp->error->all(FLERR, "compute {} requires pair_style jkr/dt", style);
  return pair;
}

/* ---------------------------------------------------------------------- */

ComputeJKRDTContacts::ComputeJKRDTContacts(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), pair(nullptr), nmax(0)
{
  if (narg != 3) error->all(FLERR, "compute jkr/dt/contacts takes no arguments: compute ID group jkr/dt/contacts");
  local_flag = 1;
  size_local_rows = 0;
  size_local_cols = NCOLS;
}

ComputeJKRDTContacts::~ComputeJKRDTContacts()
{
  memory->destroy(array_local);
}

void ComputeJKRDTContacts::init()
{
  pair = find_pair(lmp, style);
}

void ComputeJKRDTContacts::compute_local()
{
  invoked_local = update->ntimestep;
  if (!pair->contacts())
    error->all(FLERR, "compute jkr/dt/contacts: run 0 first, so that pair jkr/dt has contacts");
  NeighList *list = pair->list;
  const int nlocal = atom->nlocal;
  const tagint *tag = atom->tag;
  const int *mask = atom->mask;

  int n = 0;
  PairJKRDT::ContactView view;
  for (int pass = 0; pass < 2; pass++) {    // count, then fill
    n = 0;
    for (int ii = 0; ii < list->inum; ii++) {
      const int i = list->ilist[ii];
      for (int jj = 0; jj < list->numneigh[i]; jj++) {
        const int j = list->firstneigh[i][jj] & NEIGHMASK;
        const int p = (tag[i] < tag[j]) ? i : j;
        const int q = (p == i) ? j : i;
        if (p >= nlocal || !(mask[p] & groupbit)) continue;
        if (!pair->bonded_contact(p, q, view)) continue;
        if (pass == 1) {
          double *row = array_local[n];
          row[0] = view.id1;
          row[1] = view.id2;
          row[2] = view.delta;
          row[3] = view.a;
          row[4] = view.force;
          row[5] = view.zeta;
          row[6] = view.xi;
          row[7] = view.phi;
        }
        n++;
      }
    }
    if (pass == 0 && n > nmax) {
      memory->destroy(array_local);
      nmax = n;
      memory->create(array_local, nmax, NCOLS, "jkr/dt/contacts:array");
    }
  }
  size_local_rows = n;
}

double ComputeJKRDTContacts::memory_usage()
{
  return (double) nmax * NCOLS * sizeof(double);
}

/* ---------------------------------------------------------------------- */

ComputeJKRDTCoordination::ComputeJKRDTCoordination(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), pair(nullptr), nmax(0)
{
  if (narg != 3) error->all(FLERR, "compute jkr/dt/coordination takes no arguments: compute ID group jkr/dt/coordination");
  peratom_flag = 1;
  size_peratom_cols = 0;
}

ComputeJKRDTCoordination::~ComputeJKRDTCoordination()
{
  memory->destroy(vector_atom);
}

void ComputeJKRDTCoordination::init()
{
  pair = find_pair(lmp, style);
}

void ComputeJKRDTCoordination::compute_peratom()
{
  invoked_peratom = update->ntimestep;
  if (atom->nmax > nmax) {
    memory->destroy(vector_atom);
    nmax = atom->nmax;
    memory->create(vector_atom, nmax, "jkr/dt/coordination:vector");
  }
  const auto *C = pair->contacts();
  if (!C) error->all(FLERR, "compute jkr/dt/coordination: run 0 first, so that pair jkr/dt has contacts");
  for (int i = 0; i < atom->nlocal; i++)
    vector_atom[i] = (atom->mask[i] & groupbit) ? C->npartner[i] : 0.0;
}

double ComputeJKRDTCoordination::memory_usage()
{
  return (double) nmax * sizeof(double);
}
