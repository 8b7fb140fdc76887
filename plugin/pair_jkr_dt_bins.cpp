/* jkr/dt: bins that grow with the box.

   LAMMPS's neighbor bins and atom-sort bins tile the whole box, half a
   neighbor cutoff on a side. A shrink-wrapped box follows the fragments of
   a disruptive collision, so its volume grows as (v t)^3 while the grains
   do not: at 3000 t_c of a shattering 2 x 50000 collision the default bins
   numbered about 1000 per grain, 0.45 GB for each kind, and every
   neighbor build cleared them all.

   With 'bins bounded' (the default) the pair style widens both kinds so
   that they never number more than BINS_PER_GRAIN per grain: a bin's side
   is the default while the box is compact, and (V / (BINS_PER_GRAIN N))^(1/d)
   once it has spread (a side of the box shorter than a bin holding one).
   Memory and the cost of clearing the bins then follow
   the grains, not the empty space between them; a wider bin only adds
   candidates that the distance test turns down. Bin sizes the user gave
   (neigh_modify binsize, atom_modify sort N size) are left alone, as is
   everything with 'bins box'.

   The sizes are fitted when a run is set up (start_bins, before LAMMPS
   allocates its first bins: it never shrinks them) and before each
   reneighboring (the contact store's pre_exchange). The atom-sort bins take
   a new size at once, but LAMMPS's neighbor bins copy theirs at a run's
   start only: within one long run they would keep the first size and tile
   the growing box (measured on 2 x 10000 grains over 2500 t_c: 0.39 ->
   1.9 million bins per rank, the neighbor builds 1.5x slower). So once the
   side the bins need is BINS_OUTGROWN times this run's, the pair reports
   them outgrown; fix jkr/dt/settle then ends the run at its next check and
   the scene's deck and jkrdt.Session start the next one, which takes the
   new size. The parts are one run to round-off: a new run sorts the atoms
   and rebalances the ranks, which changes the order of the force sums.    */

#include "pair_jkr_dt.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "neighbor.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;

void PairJKRDT::fit_bins(double cutneigh)
{
  if (!bins_bounded) return;
  // user-given sizes, as they stand when the run is set up: a size this style set
  // itself is recognised by being the last one it set
  if (neighbor->binsizeflag && neighbor->binsize_user != bin_size_set) return;
  const double half_cut = 0.5 * cutneigh;
  const int dim = domain->dimension;
  // the binned region: the box and a neighbor cutoff of ghosts on either side
  double L[3] = {domain->xprd + 2.0 * cutneigh, domain->yprd + 2.0 * cutneigh,
                 domain->zprd + 2.0 * cutneigh};
  std::sort(L, L + dim);
  const double cap = BINS_PER_GRAIN * static_cast<double>(atom->natoms);
  const auto bins_of = [&](double side) {    // a side shorter than a bin holds one
    double n = 1.0;
    for (int d = 0; d < dim; d++) n *= std::max(1.0, L[d] / side);
    return n;
  };
  double size = 0.0;    // 0: LAMMPS's own (half the neighbor cutoff)
  if (half_cut > 0.0 && cap > 0.0 && bins_of(half_cut) > cap) {
    // the side that gives cap bins when the sides shorter than it hold one bin each
    for (int k = 0; k < dim; k++) {
      double wide = 1.0;
      for (int d = k; d < dim; d++) wide *= L[d];
      size = std::pow(wide / cap, 1.0 / (dim - k));
      if (size <= L[k]) break;
    }
    // LAMMPS refuses a bin over 100 times a side of the box (a flat box)
    size = std::min(size, 50.0 * L[0]);
  }
  neighbor->binsizeflag = size > 0.0 ? 1 : 0;
  neighbor->binsize_user = size;
  if (atom->sortfreq > 0 && (atom->userbinsize == 0.0 || atom->userbinsize == bin_size_set))
    atom->userbinsize = size;
  if (size > 1.25 * bin_size_logged && comm->me == 0) {
    const double binned = L[0] * L[1] * (dim == 3 ? L[2] : 1.0);    // box and ghost shell
    utils::logmesg(lmp, "pair jkr/dt: bins widened to {:.4g} m ({:.3g} x half the neighbor "
                        "cutoff) as the binned region grew to {:.4g} m^{}, to stay within {} "
                        "per grain\n",
                   size, size / half_cut, binned, dim, BINS_PER_GRAIN);
    bin_size_logged = size;
  }
  bin_size_set = size;
  if (bin_size_run > 0.0 && (size > 0.0 ? size : half_cut) > BINS_OUTGROWN * bin_size_run)
    bins_stale = true;
}

void PairJKRDT::start_bins(double cutneigh)
{
  fit_bins(cutneigh);
  // the side LAMMPS's neighbor bins take for this run: the one fit_bins set, a user's,
  // or LAMMPS's own
  bin_size_run = neighbor->binsizeflag ? neighbor->binsize_user : 0.5 * cutneigh;
  bins_stale = false;
}
