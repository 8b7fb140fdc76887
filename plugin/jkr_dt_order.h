/* jkr/dt: the owned atoms put in ID order, so that a run continued from a
   restart file is the uninterrupted run bit for bit on any rank count,
   with fix balance rcb as well.

   The order of the owned atoms decides the order of every force sum (the
   neighbor lists follow it). LAMMPS's atom sort bins the atoms in space and
   keeps their present order within a bin, and two grains in contact can
   share a bin; their present order is history (migrations between ranks,
   the last sort) that a run read from a restart file does not share. So at
   each restart step and at a run's set-up the contact store (its
   pre_exchange) migrates the atoms to their ranks and then calls
   order_by_id, and the sort that follows leaves every bin in ID order in
   the uninterrupted run and in its continuation alike. The ranks'
   sub-domains must agree as well: the scene's deck rebalances at every
   restart step, as a continued run does at its set-up.

   The atoms are moved by Atom::sort itself, which moves every per-atom
   value of every style and fix: one pass over stand-in positions that put
   each atom in a bin of its own in ID order, then the real positions go
   back. Cost: one sort per restart step.                                  */

#ifndef JKR_DT_ORDER_H
#define JKR_DT_ORDER_H

namespace LAMMPS_NS {
class LAMMPS;
}

namespace JKRDT {

// the owned atoms (all in their sub-domain) into ascending ID order (collective: no)
void order_by_id(LAMMPS_NS::LAMMPS *lmp);

// the owned atoms onto the ranks whose sub-domains hold them, as the exchange of a
// reneighboring step does, before it (collective)
void migrate_now(LAMMPS_NS::LAMMPS *lmp);

}    // namespace JKRDT

#endif
