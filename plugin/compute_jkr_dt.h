/* jkr/dt: contact output.

   compute ID group jkr/dt/contacts       local array, one row per bonded contact:
                                          id1 id2 delta a force |zeta| |xi| |phi|
                                          (for dump local; a channel that is off gives 0)
   compute ID group jkr/dt/coordination   per-atom number of bonded contacts

   A contact is listed once, by the rank that owns its atom with the smaller ID,
   if that atom is in the group.                                             */

#ifndef JKR_DT_COMPUTE_H
#define JKR_DT_COMPUTE_H

#include "compute.h"

namespace LAMMPS_NS {

class PairJKRDT;

class ComputeJKRDTContacts : public Compute {
 public:
  static constexpr int NCOLS = 8;
  ComputeJKRDTContacts(class LAMMPS *, int, char **);
  ~ComputeJKRDTContacts() override;
  void init() override;
  void compute_local() override;
  double memory_usage() override;

 private:
  PairJKRDT *pair;
  int nmax;
};

class ComputeJKRDTCoordination : public Compute {
 public:
  ComputeJKRDTCoordination(class LAMMPS *, int, char **);
  ~ComputeJKRDTCoordination() override;
  void init() override;
  void compute_peratom() override;
  double memory_usage() override;

 private:
  PairJKRDT *pair;
  int nmax;
};

}    // namespace LAMMPS_NS

#endif
