/* jkr/dt: per-contact state, in two forms.

   Between reneighborings the state lives in list order: one slot per pair
   of the pair style's neighbor list, in the order the pair loop visits
   them, holding a bonded flag and the contact's values. The pair loop reads
   and writes it sequentially, one copy per pair.

   Where atoms can move between MPI ranks, be sorted, deleted or written to
   a restart file, the state lives per atom: every bonded contact stored
   twice, once with each of its two atoms, as (partner ID, per-contact
   values). An atom's row is a segment of a chunked arena (jkr_dt_arena.h)
   as long as its own contacts, so the rows' memory follows the contacts, not
   the most contacts of any atom times the atoms; sorting and deletion move an
   atom's row pointers, not its values, and each rewrite of the rows from the
   slots builds the arena afresh, tight. This form moves with its atom between ranks (pack/unpack_exchange),
   follows atom sorting and deletion (copy_arrays) and goes into restart
   files (pack/unpack_restart).

   The per-atom rows are written from the slots (to_rows) before atoms
   migrate (pre_exchange of a reneighbor step), at the end of a run, and
   whenever a reader asks (PairJKRDT::contacts(), restart files); the slots
   are filled from the rows by partner ID after every neighbor list build
   (post_neighbor), which is also where a contact missing from the new list
   is caught and named.
   The pair style creates this fix and is the only writer; it registers
   itself through the Writer interface below, so this fix includes nothing
   of the pair style. The fix outlives
   a pair_style command that replaces jkr/dt, and then refuses to run while
   it holds contacts (they would go stale); pair_style jkr/dt takes them back.

   Per-contact values are laid out by "fields" that the kernel declares
   (StateField in jkr_dt_contact.h) and the pair style switches on only when
   some type pair needs them, so a channel that is off stores nothing. This
   fix moves the values without reading them: the kernel says how they map
   from one set of fields to another (relayout) and what a swap of the
   particles does to them (swap_particles). Values of a contact are kept in
   the canonical orientation of the pair (the atom with the smaller ID is
   "particle 1"), so both copies are identical.

   The fix's global scalar is the number of doubles stored per contact under
   the current layout (0 for the frictionless model).

   Each atom also keeps a ledger of the energy dissipated in its contacts,
   one column per channel, and of the contacts made and cut; half of each
   contact's dissipation and events goes to each of its two atoms. The
   ledger sums to values 5-9, 11 and 12 of compute pair jkr/dt, survives
   migration and restarts, and is the fix's per-atom array.                 */

#ifndef JKR_DT_FIX_CONTACTS_H
#define JKR_DT_FIX_CONTACTS_H

#include "fix.h"

#include "jkr_dt_arena.h"
#include "jkr_dt_contact.h"

#include <functional>
#include <vector>

namespace LAMMPS_NS {

class FixJKRDTContacts : public Fix {
 public:
  // what the store asks of the pair style that writes it, at the store's moments. The pair
  // style sets these when a run is set up and clears them when it is deleted, so the store
  // includes and calls nothing of it
  struct Writer {
    const void *by = nullptr;                             // the pair style that set them
    std::function<const class NeighList *()> list_of_slots;  // the list the slots follow
    std::function<void()> on_exchange;     // atoms are about to migrate (bins, box)
    std::function<void()> on_run_end;      // the end of a run (its report)
    std::function<void()> on_lost_contact;    // a stored contact left the list: say why, stop
  } writer;


  FixJKRDTContacts(class LAMMPS *, int, char **);
  ~FixJKRDTContacts() override;
  int setmask() override;
  void init() override;
  void setup_pre_exchange() override { pre_exchange(); }
  void pre_exchange() override;
  void setup_post_neighbor() override { post_neighbor(); }
  void post_neighbor() override;
  void check_atoms(bigint natoms_before);
  bigint count() const;    // bonded contacts over all ranks (collective)
  // the concatenation of every rank's ``mine``, in rank order, on every rank (collective)
  static std::vector<tagint> gather(const std::vector<tagint> &mine, MPI_Comm world);
  static std::vector<double> gather(const std::vector<double> &mine, MPI_Comm world);
  void post_run() override;
  double compute_scalar() override { return dnum; }    // doubles stored per contact
  // the passes that put the atoms in ID order so far, and their wall time on this rank (s)
  double compute_vector(int i) override { return i == 0 ? order_count : order_seconds; }

  // the fields stored per contact (a mask of the kernel's StateFields, jkr_dt_contact.h)
  void set_layout(int mask);
  int layout_mask() const { return mask; }
  JKRDT::StateLayout layout() const { return state; }

  // list-order state: slot s of the pair loop (running over ilist, then each
  // atom's neighbors) is bonded if bonded[s], with values slot_values + s * dnum
  void to_slots(const class NeighList *list);
  void to_rows();
  bool slots_follow(const class NeighList *list) const;
  bigint slots_made() const { return slot_generation; }    // changes when the slots do
  void rows_changed() { rows_stale = true; }
  unsigned char *bonded;     // per slot: 1 = a bonded contact
  double *slot_values;       // per slot: dnum values
  int *slot_first;           // per ilist entry: its first slot

  int find(int i, tagint partner_tag) const;
  double *add(int i, tagint partner_tag);
  void remove(int i, int k);
  double *contact_values(int i, int k) { return values[i] + k * dnum; }
  const double *contact_values(int i, int k) const { return values[i] + k * dnum; }

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  double memory_usage() override;

  int *npartner;        // number of bonded contacts of each atom
  tagint **partner;     // atom IDs of the partners (each atom's row, in tag_arena)
  double **values;      // per-contact values, dnum per contact (in value_arena)
  double **ledger;      // dissipated energy by channel, JKRDT::NLEDGER columns per atom
  tagint *owner;        // the atom's ID when its contacts were stored (renumbering check)
  int dnum;             // doubles per contact under the current layout

  // what the stored state was made with, kept for the pair style, which writes and reads it:
  // its record of the constants of every type pair (opaque here; it goes into restart files
  // with the contacts), so that a pair style that takes the contacts over, in this run or
  // from a restart file, can book the springs of a channel switched off; and the atom count
  // at the last run's end, so that it can tell deleted partners from renumbered ones
  std::vector<double> made_with;
  bigint natoms_at_run_end;

 private:
  int mask;             // bit f set = field f stored
  JKRDT::StateLayout state;    // where the fields sit among a contact's dnum values
  int maxpartner;       // the longest row this rank has held (sizes an exchange record)
  int nmax_alloc;       // rows allocated in the per-atom arrays
  int *capacity;        // contacts each atom's row segment has room for
  JKRDT::Arena<tagint> tag_arena;
  JKRDT::Arena<double> value_arena;

  void reserve(int i, int n);     // room for n contacts in atom i's row, keeping its own
  void fresh(int i);              // atom i's row empty, sharing no segment
  void longest_row(int n);        // a row of n contacts exists: exchange records fit it
  void set_exchange_size();
  int maxslot, slot_dnum;           // slots allocated, values per allocated slot
  int maxfirst;                     // ilist entries allocated
  const class NeighList *slot_list; // the list the slots follow ...
  bigint slot_build;                // ... as built at this step (neighbor->lastcall)
  bigint slot_generation = 0;       // to_slots() calls so far
  bool rows_stale;                  // the slots hold state the rows do not
  int slot_nlocal;                  // owned atoms when the slots were filled ...
  std::vector<tagint> slot_tag;     // ... and the IDs of all atoms then, owned and ghost
  double order_seconds = 0.0;       // wall time putting atoms in ID order ...
  int order_count = 0;              // ... at this many steps (compute_vector; the deck's end)
};

}    // namespace LAMMPS_NS

#endif
