/* jkr/dt: fix jkr/dt/settle, which ends a run when the collision has ended.

     fix ID all jkr/dt/settle N window K tolerance f [counts c] [stretch s]
                              [cap T] [depart yes|no|shadow]

   Every N steps it finds the fragments: the connected components of the
   bonded-contact graph of pair jkr/dt over all ranks. The collision has
   settled when, over the last K checks (K N steps), its largest fragment
   N_lar and its number of fragments have each varied by at most c of all
   grains, rounded down (default c = 1e-4: unchanged below 10^4 grains, 10
   grains or fragments of 10^5, where with thousands of fragments in flight
   some meet at every check; the outcome's N_lar/N holds still to c), the number of
   bonded contacts has varied by at most f of its largest value, and the
   energy dissipated over those K N steps is at most f of all the energy
   dissipated so far (restructuring by rolling and sliding has stopped: a
   remnant that still compacts keeps dissipating), and, with stretch s > 0,
   the largest fragment, where it holds at least s of all grains, has not
   grown in r_g by more than f over those checks (a body held by a neck
   without rolling or sliding resistance stretches at constant N_lar and
   contacts, dissipating nothing, and may part later; default s = 0, shape
   not watched). The run then stops at that step. A run that reaches
   simulated time T after the fix was defined without settling stops there,
   with reason "cap" (so a deck continued from a restart file gets T more).

   Each stop writes one line to the log,
     jkr/dt/settle: stop_reason settled step 123000 time 4.7e-07 N_lar 994 fragments 3 contacts 1350
   and the global vector holds: 1 state (0 running, 1 settled, 2 cap),
   2 N_lar, 3 fragments, 4 bonded contacts, 5 the step of the last check.
   The window carries over from one run to the next (a run in chunks) unless
   the step count goes back. It is carried through restart files (to a fix
   of the same ID defined after read_restart), so a run continued from one
   with the remaining cap stops where the uninterrupted run would have.

   depart yes: at each check, a fragment that has left the collision for
   good departs (fix_jkr_dt_settle_depart.cpp has the rule): its grains join
   group jkrdt_departed and leave the groups of the time integrators, so they
   keep their positions, velocities, spins and contacts but no longer move or
   interact; the box stops growing with them. Their energy stays in ke,
   erotate and pe (constant), so the conserved total is unchanged, and their
   contacts still count in the fragments. Vector values 6 and 7 are the
   departed grains and fragments; where the deck defines the per-atom vector
   departed_at (fix property/atom d_departed_at), each departed grain's time of
   departure goes there. depart shadow only writes, once per
   fragment, the line "jkr/dt/settle: would depart step S label L size N"
   (L the smallest atom ID) so that the rule can be checked against a run
   that keeps every fragment.

   The fix also ends a run, still unsettled, at a check where pair jkr/dt
   reports its neighbor bins outgrown by the spreading box (LAMMPS takes the
   bin size at a run's start only; pair_jkr_dt_bins.cpp), writing
     jkr/dt/settle: new run for wider bins step 123000
   with vector value 8 set to 1 until the next run starts: the scene's deck
   and jkrdt.Session then run on from that step with a new run.

   table FILE [append yes|no]: at every check (and at the first set-up) rank 0
   writes one row of the fragments to FILE, a CSV table
   (fix_jkr_dt_settle_table.cpp has the columns), so that the timeline of a
   collision needs no dumps; append yes adds to FILE (a run continued from a
   restart file), no starts it anew.                                        */

#ifndef JKR_DT_FIX_SETTLE_H
#define JKR_DT_FIX_SETTLE_H

#include "fix.h"

#include "fix_jkr_dt_settle_depart.h"
#include "fix_jkr_dt_settle_table.h"
#include "jkr_dt_fragments.h"

#include <deque>
#include <memory>
#include <string>

namespace LAMMPS_NS {

class FixJKRDTSettle : public Fix {
 public:
  enum State { RUNNING = 0, SETTLED, CAP };
  struct Partition {
    bigint n_largest, n_fragments, contacts;
    double dissipated;         // all channels of the contact fix's ledger, summed over ranks
    double gyration_radius;    // r_g of the largest fragment, m (< 0: unknown)
  };

  FixJKRDTSettle(class LAMMPS *, int, char **);
  ~FixJKRDTSettle() override;
  int setmask() override;
  void init() override;
  void post_constructor() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

 private:
  int window;                    // K checks
  double tolerance;              // f: relative change of the contact count
  double counts;                 // c: change of N_lar and of the fragment count, of all grains
  double stretch;                // s: shape watched in a largest fragment of s of all grains
  double cap;                    // simulated time at which the run stops unsettled; < 0 none
  int state;
  bool rerun;                    // this run was ended for the pair's wider bins
  bigint last_check;
  Partition now;
  int largest;                      // the root of the largest fragment at the last check
  std::deque<Partition> history;    // the last K + 1 checks

  using Graph = FragmentGraph;    // the fragments (jkr_dt_fragments.h)
  Partition partition(Graph &graph);
  double gyration_radius(Graph &graph, int root) const;
  bool stretched() const;
  SettleDeparture departure;     // depart yes|no|shadow (fix_jkr_dt_settle_depart.*)
  // the simulated time counts from an origin (time, step, dt) taken when the fix is defined
  // and carried through restart files, so that a continued run's times are the
  // uninterrupted run's to the bit (LAMMPS's own atime restarts from the file's step);
  // LAMMPS's count where dt has changed since
  double time_origin, dt_origin;
  bigint step_origin;
  double simulated_time() const;
  std::string table_path;        // the in-run table; empty: none
  bool table_append;
  std::unique_ptr<SettleTable> table;    // (fix_jkr_dt_settle_table.*)
  void write_check(Graph &graph);
  void stop(int reason);
};

}    // namespace LAMMPS_NS

#endif
