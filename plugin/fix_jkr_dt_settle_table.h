/* jkr/dt: the in-run table of fix jkr/dt/settle (table FILE): one CSV row
   per check of the fragments it has found (fix_jkr_dt_settle_table.cpp has
   the columns). Rank 0 writes; every rank takes part in a row.             */

#ifndef JKR_DT_FIX_SETTLE_TABLE_H
#define JKR_DT_FIX_SETTLE_TABLE_H

#include "pointers.h"

#include "jkr_dt_fragments.h"

#include <cstdio>
#include <string>

namespace LAMMPS_NS {

class SettleTable : protected Pointers {
 public:
  // what the check knows beyond the fragments
  struct Check {
    double time;                                 // simulated time, s
    bigint n_fragments, contacts;
    double departed_grains, departed_fragments;    // so far
    int largest;                                 // the largest fragment's root (-1: none)
    double gyration_radius;                      // its r_g, m (eq. 50)
  };
  // opens FILE on rank 0 (append: add to it) and starts the wall clock of the table
  SettleTable(class LAMMPS *lmp, const std::string &path, bool append);
  ~SettleTable() override;
  void write(FragmentGraph &graph, const Check &check);    // collective
  // the wall column: seconds since the table was opened, plus what a run continued from
  // a restart file had spent before it (continue_from), so it goes on, not back to 0
  double wall() const;
  void continue_from(double seconds);

 private:
  std::string path;
  FILE *file;
  double start;    // wall-clock time the table was opened, less the time continued from
};

}    // namespace LAMMPS_NS

#endif
