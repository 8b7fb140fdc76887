/* jkr/dt: the owned atoms in ID order. See jkr_dt_order.h. */

#include "jkr_dt_order.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "lammps.h"

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

using namespace LAMMPS_NS;

void JKRDT::migrate_now(LAMMPS *lmp)
{
  // as Verlet's reneighboring does before its exchange: atoms into the (shrink-wrapped)
  // box, the box and the sub-domains fitted, then the exchange; Verlet's own exchange
  // that follows finds nothing to move
  lmp->domain->pbc();
  if (lmp->domain->box_change) {
    lmp->domain->reset_box();
    lmp->comm->setup();
  }
  lmp->comm->exchange();
}

void JKRDT::order_by_id(LAMMPS *lmp)
{
  Atom *atom = lmp->atom;
  Domain *domain = lmp->domain;
  const int nlocal = atom->nlocal;
  if (nlocal < 2) return;

  std::vector<std::pair<tagint, int>> by_id(nlocal);
  for (int i = 0; i < nlocal; i++) by_id[i] = {atom->tag[i], i};
  std::sort(by_id.begin(), by_id.end());
  std::vector<std::array<double, 3>> real(nlocal);    // the k-th ID's position
  for (int k = 0; k < nlocal; k++) {
    const double *x = atom->x[by_id[k].second];
    real[k] = {x[0], x[1], x[2]};
  }

  // bins of side b over the sub-domain, as Atom::sort lays them out, at least one per atom
  const int dim = domain->dimension;
  double lo[3], L[3];
  for (int d = 0; d < 3; d++) {
    lo[d] = domain->sublo[d];
    L[d] = domain->subhi[d] - domain->sublo[d];
  }
  int n[3] = {1, 1, 1};
  const auto count = [&](double b) {
    double total = 1.0;
    for (int d = 0; d < dim; d++) {
      n[d] = std::max(1, static_cast<int>(L[d] * (1.0 / b)));    // Atom's own count
      total *= n[d];
    }
    return total;
  };
  double b = std::max({L[0], L[1], dim == 3 ? L[2] : 0.0});
  while (count(b) < nlocal) b *= 0.8;

  // stand-in positions: the k-th ID at the centre of bin k
  for (int k = 0; k < nlocal; k++) {
    double *x = atom->x[by_id[k].second];
    const int ix = k % n[0], iy = (k / n[0]) % n[1], iz = k / (n[0] * n[1]);
    x[0] = lo[0] + (ix + 0.5) * L[0] / n[0];
    x[1] = lo[1] + (iy + 0.5) * L[1] / n[1];
    x[2] = dim == 3 ? lo[2] + (iz + 0.5) * L[2] / n[2] : real[k][2];
  }
  const int sortfreq = atom->sortfreq;
  const bigint nextsort = atom->nextsort;
  const double userbinsize = atom->userbinsize;
  atom->sortfreq = 1;    // Atom::setup lays out the bins only for a sorting atom style
  atom->userbinsize = b;
  atom->setup();
  atom->sort();
  atom->sortfreq = sortfreq;
  atom->nextsort = nextsort;    // the real sort still runs where it was due
  atom->userbinsize = userbinsize;
  if (sortfreq > 0) atom->setup();

  bool ordered = true;
  for (int k = 0; k < nlocal; k++) {
    ordered = ordered && atom->tag[k] == by_id[k].first;
    atom->x[k][0] = real[k][0];
    atom->x[k][1] = real[k][1];
    atom->x[k][2] = real[k][2];
  }
  if (!ordered)
    lmp->error->one(FLERR, "pair jkr/dt: the owned atoms could not be put in ID order "
                           "(internal error); run with 'atom_modify sort 0 0.0'");
}
