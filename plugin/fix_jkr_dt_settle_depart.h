/* jkr/dt: the departure rule of fix jkr/dt/settle (depart yes|shadow): which
   fragments have left the collision for good, and for depart yes their
   grains' move to the departed group (fix_jkr_dt_settle_depart.cpp has the
   rule).                                                                    */

#ifndef JKR_DT_FIX_SETTLE_DEPART_H
#define JKR_DT_FIX_SETTLE_DEPART_H

#include "pointers.h"

#include "jkr_dt_fragments.h"

#include <unordered_set>
#include <vector>

namespace LAMMPS_NS {

class SettleDeparture : protected Pointers {
 public:
  enum Mode { NO = 0, YES, SHADOW };
  // the per-atom custom vector that, where a deck defines it, receives each departed
  // grain's time of departure (s): fix ID all property/atom d_departed_at
  static constexpr const char *DEPARTED_AT = "departed_at";

  explicit SettleDeparture(class LAMMPS *lmp) : Pointers(lmp) {}
  int mode = NO;
  int departed_bit = 0;          // the departed group's mask bit
  int moving_bits = 0;           // the time integrators' groups' bits, which a departed grain leaves
  double quiet_speed = 0.0;      // a grain this fast against its fragment can break a contact
  double break_energy = 0.0;     // E_break of the weakest contact
  double departed_grains = 0.0, departed_fragments = 0.0;    // so far (depart yes)

  // the check's departures (collective). npartner: the bonded contacts of each owned atom;
  // now: the simulated time. True if grains departed (depart yes): the ghosts' masks then
  // need a reneighboring
  bool find(FragmentGraph &graph, const int *npartner, double now);

 private:
  std::unordered_set<tagint> shadowed;    // fragments reported by depart shadow

  // find() in its steps, each over what the check knows so far (a Census)
  struct Census;
  void number_bodies(Census &c, FragmentGraph &graph) const;
  void sum_motion(Census &c, const FragmentGraph &graph) const;
  void fit_spin_and_reach(Census &c) const;
  void gather_hot_grains(Census &c, const int *npartner) const;
  void add_single_grains(Census &c) const;
  std::vector<int> who_leaves(const Census &c) const;
  bool depart(const Census &c, const std::vector<int> &leaves, double now);
};

}    // namespace LAMMPS_NS

#endif
