/* jkr/dt: the in-run table of fix jkr/dt/settle (table FILE).

   One row per check, from the fragments the check has just found, in the
   papers' measures (3D BPCA paper sec. 3; Wada et al. 2007 eqs. 50, 56-57):

     step, time                 the check
     n_total                    grains
     n_largest, n_second        the largest and second-largest fragment; of
                                fragments equally large, the one holding the
                                smallest atom ID ranks first
     n_fragments                fragments, single grains included
     contacts                   bonded contacts of all grains
     contacts_largest           bonded contacts inside the largest fragment
                                (n_con = contacts_largest / n_largest)
     gyration_radius_largest    r_g of the largest fragment (equal grains), m
     N_cum_1, N_cum_4, N_cum_16 grains in fragments of at most 1, 4, 16 grains
     departed_grains, departed_fragments   what has departed so far
     wall                       wall-clock seconds since the fix was defined, and in a
                                run continued from a restart file, since the run began
     memory_mb, peak_rss_mb     the largest over the ranks of LAMMPS's own count
                                of its memory and of the peak resident size, MB

   so that the cost of a run against simulated time, and its memory, come
   with every run.

   Every rank holds the whole contact graph; the fix finds the largest
   fragment and its r_g (which its rule watches) and hands both over.
   Rows are flushed as they are written: a run that is killed leaves whole
   rows, and one continued from a restart file appends rows for steps that
   may already be there (the later row is the one that counts).             */

#include "fix_jkr_dt_settle_table.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "info.h"
#include "platform.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <vector>

using namespace LAMMPS_NS;

SettleTable::SettleTable(LAMMPS *lmp, const std::string &path_, bool append) :
    Pointers(lmp), path(path_), file(nullptr), start(platform::walltime())
{
  if (comm->me != 0) return;
  file = fopen(path.c_str(), append ? "a" : "w");
  if (!file)
    error->one(FLERR, "fix jkr/dt/settle: cannot write the table {}: {}; check that its "
               "directory exists and is writable", path, utils::getsyserror());
  if (ftell(file) == 0)
    fputs("step,time,n_total,n_largest,n_second,n_fragments,contacts,contacts_largest,"
          "gyration_radius_largest,N_cum_1,N_cum_4,N_cum_16,departed_grains,"
          "departed_fragments,wall,memory_mb,peak_rss_mb\n", file);
}

SettleTable::~SettleTable()
{
  if (file) fclose(file);
}

double SettleTable::wall() const
{
  return platform::walltime() - start;
}

void SettleTable::continue_from(double seconds)
{
  start = platform::walltime() - seconds;
}

void SettleTable::write(FragmentGraph &graph, const Check &check)
{
  // the fragments of more than one grain, by root; the largest is the check's
  const int nodes = static_cast<int>(graph.parent.size());
  const int largest = check.largest;
  const bigint singles = atom->natoms - static_cast<bigint>(nodes);
  bigint cum4 = singles, cum16 = singles, second = singles > 0 ? 1 : 0;
  for (int k = 0; k < nodes; k++) {
    if (graph.parent[k] != k) continue;
    const bigint n = graph.size[k];
    if (n <= 4) cum4 += n;
    if (n <= 16) cum16 += n;
    if (k != largest) second = std::max(second, n);
  }
  bigint first = largest >= 0 ? graph.size[largest] : (atom->natoms > 0 ? 1 : 0);
  if (largest < 0) second = atom->natoms > 1 ? 1 : 0;    // every fragment is one grain
  bigint inside = 0;
  for (size_t e = 0; largest >= 0 && e < graph.edges.size(); e += 2)
    if (graph.root(graph.index.at(graph.edges[e])) == largest) inside++;
  double memory[3], largest_memory[2];
  Info(lmp).get_memory_info(memory);    // MB: LAMMPS's count, the heap, the peak resident size
  memory[1] = memory[2];
  MPI_Allreduce(memory, largest_memory, 2, MPI_DOUBLE, MPI_MAX, world);
  if (comm->me != 0 || !file) return;
  fmt::print(file,
             "{},{:.17g},{},{},{},{},{},{},{:.17g},{},{},{},{:.17g},{:.17g},{:.6g},{:.6g},{:.6g}\n",
             update->ntimestep, check.time, atom->natoms, first, second, check.n_fragments,
             check.contacts, inside, check.gyration_radius, singles, cum4, cum16,
             check.departed_grains,
             check.departed_fragments, wall(), largest_memory[0],
             largest_memory[1]);
  fflush(file);
}
