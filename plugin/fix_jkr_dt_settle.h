/* jkr/dt: fix jkr/dt/settle, which ends a run when the collision has ended.

     fix ID all jkr/dt/settle N window K tolerance f [cap T]

   Every N steps it finds the fragments: the connected components of the
   bonded-contact graph of pair jkr/dt over all ranks. The collision has
   settled when, over the last K checks (K N steps), the partition has kept
   its largest fragment N_lar and its number of fragments, the number of
   bonded contacts has varied by at most f of its largest value, and the
   energy dissipated over those K N steps is at most f of all the energy
   dissipated so far (restructuring by rolling and sliding has stopped: a
   remnant that still compacts keeps dissipating). The run then stops at
   that step. A run that reaches simulated time T after the fix was defined
   without settling stops there, with reason "cap" (so a deck continued from
   a restart file gets T more).

   Each stop writes one line to the log,
     jkr/dt/settle: stop_reason settled step 123000 time 4.7e-07 N_lar 994 fragments 3 contacts 1350
   and the global vector holds: 1 state (0 running, 1 settled, 2 cap),
   2 N_lar, 3 fragments, 4 bonded contacts, 5 the step of the last check.
   The window carries over from one run to the next (a run in chunks) unless
   the step count goes back. It is carried through restart files (to a fix
   of the same ID defined after read_restart), so a run continued from one
   with the remaining cap stops where the uninterrupted run would have.    */

#ifndef JKR_DT_FIX_SETTLE_H
#define JKR_DT_FIX_SETTLE_H

#include "fix.h"

#include <deque>

namespace LAMMPS_NS {

class FixJKRDTSettle : public Fix {
 public:
  enum State { RUNNING = 0, SETTLED, CAP };
  struct Partition {
    bigint n_largest, n_fragments, contacts;
    double dissipated;    // all channels of the contact fix's ledger, summed over ranks
  };

  FixJKRDTSettle(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

 private:
  int window;                    // K checks
  double tolerance;              // f: relative change of the contact count
  double cap;                    // simulated time at which the run stops unsettled; < 0 none
  int state;
  bigint last_check;
  Partition now;
  std::deque<Partition> history;    // the last K + 1 checks

  Partition partition() const;
  double simulated_time() const;
  void stop(int reason);
};

}    // namespace LAMMPS_NS

#endif
