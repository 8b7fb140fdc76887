/* jkr/dt: per-contact state storage. See fix_jkr_dt_contacts.h. */

#include "fix_jkr_dt_contacts.h"


#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "output.h"
#include "update.h"

#include "jkr_dt_order.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>
#include <cstring>

using namespace LAMMPS_NS;

static constexpr int INITIAL_CAPACITY = 2;    // a new row's room: BPCA grains hold ~2 contacts

/* ---------------------------------------------------------------------- */

FixJKRDTContacts::FixJKRDTContacts(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), npartner(nullptr), partner(nullptr), values(nullptr), ledger(nullptr),
    owner(nullptr), dnum(0), bonded(nullptr), slot_values(nullptr), slot_first(nullptr),
    natoms_at_run_end(0), mask(0), maxpartner(INITIAL_CAPACITY), nmax_alloc(0), capacity(nullptr),
    maxslot(0), slot_dnum(0), maxfirst(0), slot_list(nullptr), slot_build(-1), rows_stale(false),
    slot_nlocal(0)
{
  if (narg != 4)
    error->all(FLERR,
               "fix jkr/dt/contacts is created by pair_style jkr/dt; do not define it by hand");
  mask = utils::inumeric(FLERR, arg[3], false, lmp);
  state = JKRDT::state_layout(mask);
  dnum = state.dnum;

  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
  peratom_flag = 1;
  size_peratom_cols = JKRDT::NLEDGER;
  peratom_freq = 1;
  scalar_flag = 1;
  global_freq = 1;
  extscalar = 0;
  vector_flag = 1;    // what putting atoms in ID order has cost: passes, seconds (rank 0)
  size_vector = 2;
  extvector = 0;

  // an atom's exchange record grows with its contacts: Comm and Irregular size their
  // buffers from maxexchange, which set_exchange_size() keeps at the largest record
  maxexchange_dynamic = 1;
  set_exchange_size();

  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
}

/* ---------------------------------------------------------------------- */

FixJKRDTContacts::~FixJKRDTContacts()
{
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(npartner);
  memory->destroy(capacity);
  memory->sfree(partner);    // arrays of row pointers (the rows are the arenas')
  memory->sfree(values);
  memory->destroy(ledger);
  memory->destroy(owner);
  memory->destroy(bonded);
  memory->destroy(slot_values);
  memory->destroy(slot_first);
}

/* ----------------------------------------------------------------------
   between runs, the contacts follow their atoms (called by the pair style):
   a contact whose partner was deleted is removed, and partner IDs that a
   command renumbered (delete_atoms ... compress yes, reset_atoms id) are
   carried to the new IDs. Each atom with contacts knows its own ID at the
   time they were stored (owner), so the old-to-new map is the set of
   (owner, tag) of all such atoms. A contact whose two atoms swap their ID
   order swaps its pointers n1 <-> n2 (the twisting angle of eq. (24) and
   the damping force do not change with the labels).
------------------------------------------------------------------------- */

void FixJKRDTContacts::check_atoms(bigint natoms_before)
{
  const int nlocal = atom->nlocal;
  const tagint *tag = atom->tag;
  int moved = 0;
  for (int i = 0; i < nlocal; i++)
    if (npartner[i] > 0 && owner[i] != tag[i]) moved++;
  // atoms renumbered, and whether atoms were deleted, over all ranks
  int changed[2] = {moved, natoms_before > 0 && atom->natoms < natoms_before};
  int any[2] = {0, 0};
  MPI_Allreduce(changed, any, 2, MPI_INT, MPI_SUM, world);
  if (!any[0] && !any[1]) return;

  std::vector<tagint> mine;
  for (int i = 0; i < nlocal; i++)
    if (npartner[i] > 0) {
      mine.push_back(owner[i]);
      mine.push_back(tag[i]);
    }
  const std::vector<tagint> flat = gather(mine, world);
  std::vector<std::pair<tagint, tagint>> renamed;    // (ID when stored, ID now)
  for (size_t e = 0; e < flat.size(); e += 2) renamed.emplace_back(flat[e], flat[e + 1]);
  std::sort(renamed.begin(), renamed.end());

  bigint removed = 0, all_removed = 0;
  for (int i = 0; i < nlocal; i++) {
    for (int k = npartner[i] - 1; k >= 0; k--) {
      const tagint was = partner[i][k];
      auto it = std::lower_bound(renamed.begin(), renamed.end(),
                                 std::make_pair(was, std::numeric_limits<tagint>::min()));
      if (it == renamed.end() || it->first != was) {    // the partner is gone
        remove(i, k);
        removed++;
        continue;
      }
      const tagint now = it->second;
      if ((owner[i] < was) != (tag[i] < now)) JKRDT::swap_particles(contact_values(i, k), state);
      partner[i][k] = now;
    }
    owner[i] = tag[i];
  }
  MPI_Allreduce(&removed, &all_removed, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (all_removed && !any[1])
    error->all(FLERR,
               "pair jkr/dt: {} stored contacts point at atoms that no longer store them, "
               "though no atom was deleted: the contact state is inconsistent",
               all_removed);
  if (comm->me == 0) {
    if (all_removed)
      utils::logmesg(lmp, "pair jkr/dt: {} contacts with deleted atoms removed\n", all_removed);
    if (any[0])
      utils::logmesg(lmp, "pair jkr/dt: the contacts of {} renumbered atoms follow their new IDs\n",
                     any[0]);
  }
}

/* ----------------------------------------------------------------------
   a run without pair jkr/dt would move the atoms under stored contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::init()
{
  if (writer.by) return;    // pair jkr/dt is set up for this run
  const bigint stored = count();
  if (stored > 0)
    error->all(FLERR,
               "pair jkr/dt: the pair style is now {}, but {} bonded contacts of jkr/dt are "
               "stored; a run without jkr/dt would leave them stale. Keep pair_style jkr/dt "
               "(use pair_style hybrid/overlay to add another), or 'unfix {}' to drop them",
               force->pair_style ? force->pair_style : "none", stored, id);
}

bigint FixJKRDTContacts::count() const
{
  bigint mine = 0, all = 0;
  for (int i = 0; i < atom->nlocal; i++) mine += npartner[i];
  MPI_Allreduce(&mine, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  return all / 2;    // each contact is stored with both of its atoms
}

namespace {
// the concatenation of every rank's values, in rank order, on every rank
template <typename T>
std::vector<T> gather_all(const std::vector<T> &mine, MPI_Datatype type, MPI_Comm world)
{
  int nprocs = 1;
  MPI_Comm_size(world, &nprocs);
  const int n = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int r = 1; r < nprocs; r++) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<T> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, type, all.data(), counts.data(), displs.data(), type, world);
  return all;
}
}    // namespace

std::vector<tagint> FixJKRDTContacts::gather(const std::vector<tagint> &mine, MPI_Comm world)
{
  return gather_all(mine, MPI_LMP_TAGINT, world);
}

std::vector<double> FixJKRDTContacts::gather(const std::vector<double> &mine, MPI_Comm world)
{
  return gather_all(mine, MPI_DOUBLE, world);
}

/* ----------------------------------------------------------------------
   end of a run: the rows take the state, and the pair style reports how
   well the step resolved contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::post_run()
{
  to_rows();    // between runs the rows are the state
  if (writer.by) writer.on_run_end();
}

/* ----------------------------------------------------------------------
   switch to a new set of fields, keeping the values of fields in both
------------------------------------------------------------------------- */

void FixJKRDTContacts::set_layout(int newmask)
{
  if (newmask == mask) return;
  const JKRDT::StateLayout next = JKRDT::state_layout(newmask);
  const int newdnum = next.dnum;
  // the owned atoms' values into a fresh arena, each row as long as its segment
  JKRDT::Arena<double> vals;
  for (int i = 0; i < atom->nlocal; i++) {
    double *row = (newdnum && capacity[i]) ? vals.take((size_t) capacity[i] * newdnum) : nullptr;
    for (int k = 0; row && k < npartner[i]; k++)
      JKRDT::relayout(dnum ? values[i] + k * dnum : nullptr, state, row + k * newdnum, next);
    values[i] = row;
  }
  for (int i = atom->nlocal; i < nmax_alloc; i++) fresh(i);
  value_arena.swap(vals);
  mask = newmask;
  state = next;
  dnum = newdnum;
  set_exchange_size();
}

int FixJKRDTContacts::setmask()
{
  return FixConst::PRE_EXCHANGE | FixConst::POST_NEIGHBOR;
}

/* ----------------------------------------------------------------------
   before atoms migrate: the state into the per-atom rows, and the pair
   style's bins fitted to the box
------------------------------------------------------------------------- */

void FixJKRDTContacts::pre_exchange()
{
  to_rows();
  // at a run's set-up and at each restart step (LAMMPS reneighbors there): the atoms on
  // their ranks and in ID order, as a run continued from this step's restart file will
  // have them (jkr_dt_order.h)
  const bool restart_step = output->restart_flag && update->ntimestep == output->next_restart;
  if (update->setupflag || restart_step) {
    const double t0 = MPI_Wtime();
    JKRDT::migrate_now(lmp);
    JKRDT::order_by_id(lmp);
    order_seconds += MPI_Wtime() - t0;
    ++order_count;
  }
  if (writer.by) writer.on_exchange();
}

/* ----------------------------------------------------------------------
   after every neighbor list build: the slots of the pair's new list
------------------------------------------------------------------------- */

void FixJKRDTContacts::post_neighbor()
{
  if (writer.by && writer.list_of_slots()) to_slots(writer.list_of_slots());
}

bool FixJKRDTContacts::slots_follow(const NeighList *list) const
{
  return list == slot_list && slot_build == neighbor->lastcall;
}

/* ----------------------------------------------------------------------
   rows -> slots, by partner ID. Atom i of the half list is always owned;
   a pair of two owned atoms must be stored by both, and every stored
   contact must be found in the list, or it is named and the run stops
------------------------------------------------------------------------- */

void FixJKRDTContacts::to_slots(const NeighList *list)
{
  if (rows_stale)
    error->one(FLERR, "pair jkr/dt: the contact state was not written back before the "
                      "neighbor list was rebuilt (internal error)");
  const int inum = list->inum;
  const int *ilist = list->ilist, *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;
  const int nlocal = atom->nlocal;
  const tagint *tag = atom->tag;

  if (inum + 1 > maxfirst) {
    maxfirst = inum + 1 + inum / 4;
    memory->destroy(slot_first);
    memory->create(slot_first, maxfirst, "jkr/dt:slot_first");
  }
  int n = 0;
  for (int ii = 0; ii < inum; ii++) {
    slot_first[ii] = n;
    n += numneigh[ilist[ii]];
  }
  slot_first[inum] = n;
  if (n > maxslot || dnum != slot_dnum) {
    maxslot = std::max(maxslot, n + n / 4 + 16);
    slot_dnum = dnum;
    memory->destroy(bonded);
    memory->destroy(slot_values);
    memory->create(bonded, maxslot, "jkr/dt:bonded");
    if (dnum) memory->create(slot_values, (bigint) maxslot * dnum, "jkr/dt:slot_values");
  }

  std::vector<int> found(nlocal, 0);
  bool one_sided = false;
  tagint one_sided_ids[2] = {0, 0};
  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    const int *jlist = firstneigh[i];
    int s = slot_first[ii];
    for (int jj = 0; jj < numneigh[i]; jj++, s++) {
      const int j = jlist[jj] & NEIGHMASK;
      const int k = find(i, tag[j]);
      if (j < nlocal && (k >= 0) != (find(j, tag[i]) >= 0)) {
        one_sided = true;
        one_sided_ids[0] = tag[i];
        one_sided_ids[1] = tag[j];
      }
      bonded[s] = k >= 0;
      if (k < 0) continue;
      found[i]++;
      if (j < nlocal) found[j]++;
      if (dnum) std::copy_n(contact_values(i, k), dnum, slot_values + (bigint) s * dnum);
    }
  }
  if (one_sided)
    error->one(FLERR, "pair jkr/dt: contact {}-{} is stored with only one of its atoms",
               one_sided_ids[0], one_sided_ids[1]);
  for (int i = 0; i < nlocal; i++)
    if (found[i] != npartner[i]) {
      writer.on_lost_contact();    // names the contact and why; does not return
    }
  slot_list = list;
  slot_build = neighbor->lastcall;
  slot_generation++;
  // the atoms as the list saw them: a fix that migrates atoms before this fix's
  // pre_exchange (fix balance rcb) may append arrivals, which take the ghosts' places,
  // before the rows are written back
  slot_nlocal = nlocal;
  slot_tag.assign(tag, tag + nlocal + atom->nghost);
}

// fn(i, j, s) for each bonded slot s of the list, i and j its atoms (i owned)
template <typename F>
static void each_bonded_slot(const NeighList *list, const int *slot_first,
                             const unsigned char *bonded, F fn)
{
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    bigint s = slot_first[ii];
    for (int jj = 0; jj < list->numneigh[i]; jj++, s++)
      if (bonded[s]) fn(i, jlist[jj] & NEIGHMASK, s);
  }
}

/* ----------------------------------------------------------------------
   slots -> rows: each owned atom's row becomes the bonded slots it is in
------------------------------------------------------------------------- */

void FixJKRDTContacts::to_rows()
{
  if (!rows_stale) return;
  rows_stale = false;
  const NeighList *list = slot_list;
  // the atoms the list was built over; atoms appended since (arrived from another rank
  // while this rank sent none) brought their rows with them and are left alone
  const int nlocal = slot_nlocal;
  if (atom->nlocal < nlocal)
    error->one(FLERR, "pair jkr/dt: atoms left this rank before their contacts were written "
                      "back (internal error)");
  const tagint *tag = slot_tag.data();

  // a fresh arena, tight: each atom of the list gets room for its bonded slots, and an
  // atom that arrived since keeps its row; every other row pointer is dropped
  std::vector<int> count(nlocal, 0);
  each_bonded_slot(list, slot_first, bonded, [&](int i, int j, bigint) {
    count[i]++;
    if (j < nlocal) count[j]++;
  });
  JKRDT::Arena<tagint> tags;
  JKRDT::Arena<double> vals;
  auto place = [&](int i, int n) {
    partner[i] = n ? tags.take(n) : nullptr;
    values[i] = (n && dnum) ? vals.take((size_t) n * dnum) : nullptr;
    capacity[i] = n;
  };
  for (int i = nlocal; i < atom->nlocal; i++) {
    const tagint *p = partner[i];
    const double *v = values[i];
    place(i, npartner[i]);
    std::copy_n(p, npartner[i], partner[i]);
    if (dnum) std::copy_n(v, (size_t) npartner[i] * dnum, values[i]);
  }
  int longest = 0;
  for (int i = 0; i < nlocal; i++) {
    place(i, count[i]);
    npartner[i] = 0;
    longest = std::max(longest, count[i]);
  }
  for (int i = atom->nlocal; i < nmax_alloc; i++) fresh(i);
  tag_arena.swap(tags);
  value_arena.swap(vals);
  longest_row(longest);

  each_bonded_slot(list, slot_first, bonded, [&](int i, int j, bigint s) {
    const double *v = dnum ? slot_values + s * dnum : nullptr;
    double *row = add(i, tag[j]);
    if (v) std::copy_n(v, dnum, row);
    if (j < nlocal) {
      row = add(j, tag[i]);
      if (v) std::copy_n(v, dnum, row);
    }
  });
}

/* ----------------------------------------------------------------------
   look-up, insertion and removal of the contacts of atom i
------------------------------------------------------------------------- */

int FixJKRDTContacts::find(int i, tagint partner_tag) const
{
  const tagint *row = partner[i];
  for (int k = 0; k < npartner[i]; k++)
    if (row[k] == partner_tag) return k;
  return -1;
}

double *FixJKRDTContacts::add(int i, tagint partner_tag)
{
  reserve(i, npartner[i] + 1);
  owner[i] = atom->tag[i];
  const int k = npartner[i]++;
  partner[i][k] = partner_tag;
  if (dnum == 0) return nullptr;
  double *v = values[i] + k * dnum;
  std::fill(v, v + dnum, 0.0);
  return v;
}

void FixJKRDTContacts::remove(int i, int k)
{
  const int last = --npartner[i];
  if (k == last) return;
  partner[i][k] = partner[i][last];
  if (dnum) std::copy_n(values[i] + last * dnum, dnum, values[i] + k * dnum);
}

/* ----------------------------------------------------------------------
   an atom's row grows into a new segment, twice as long, and keeps its
   contacts; the old segment stays in the arena until the next rewrite
------------------------------------------------------------------------- */

void FixJKRDTContacts::reserve(int i, int n)
{
  if (n <= capacity[i]) return;
  const int room = std::max({n, 2 * capacity[i], INITIAL_CAPACITY});
  tagint *p = tag_arena.take(room);
  std::copy_n(partner[i], npartner[i], p);
  partner[i] = p;
  if (dnum) {
    double *v = value_arena.take((size_t) room * dnum);
    std::copy_n(values[i], (size_t) npartner[i] * dnum, v);
    values[i] = v;
  }
  capacity[i] = room;
  longest_row(n);
}

void FixJKRDTContacts::fresh(int i)
{
  npartner[i] = capacity[i] = 0;
  partner[i] = nullptr;
  values[i] = nullptr;
}

void FixJKRDTContacts::longest_row(int n)
{
  if (n <= maxpartner) return;
  maxpartner = std::max(n, maxpartner + maxpartner / 2);
  set_exchange_size();
}

// doubles of the largest exchange record (pack_exchange): count, partner IDs, values,
// ledger, owner ID
void FixJKRDTContacts::set_exchange_size()
{
  maxexchange = 2 + JKRDT::NLEDGER + maxpartner * (1 + dnum);
}

/* ----------------------------------------------------------------------
   per-atom callbacks: growth, copy (sorting, deletion), new atoms
------------------------------------------------------------------------- */

void FixJKRDTContacts::grow_arrays(int nmax)
{
  const int oldmax = nmax_alloc;
  memory->grow(npartner, nmax, "jkr/dt:npartner");
  memory->grow(capacity, nmax, "jkr/dt:capacity");
  partner = (tagint **) memory->srealloc(partner, sizeof(tagint *) * nmax, "jkr/dt:partner");
  values = (double **) memory->srealloc(values, sizeof(double *) * nmax, "jkr/dt:values");
  memory->grow(ledger, nmax, JKRDT::NLEDGER, "jkr/dt:ledger");
  memory->grow(owner, nmax, "jkr/dt:owner");
  nmax_alloc = nmax;
  for (int i = oldmax; i < nmax; i++) set_arrays(i);
  array_atom = ledger;
}

void FixJKRDTContacts::copy_arrays(int i, int j, int /*delflag*/)
{
  to_rows();    // atoms are about to be moved (sort, deletion): the rows take the state first
  // j takes i's row segment; i is overwritten or gone next (sorting, deletion), and a
  // new atom in its place starts a row of its own (set_arrays, unpack_exchange)
  npartner[j] = npartner[i];
  capacity[j] = capacity[i];
  partner[j] = partner[i];
  values[j] = values[i];
  std::copy_n(ledger[i], (int) JKRDT::NLEDGER, ledger[j]);
  owner[j] = owner[i];
}

void FixJKRDTContacts::set_arrays(int i)
{
  fresh(i);
  owner[i] = 0;
  std::fill(ledger[i], ledger[i] + JKRDT::NLEDGER, 0.0);
}

/* ----------------------------------------------------------------------
   migration between ranks: count, partner IDs, values, ledger, owner ID
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_exchange(int i, double *buf)
{
  to_rows();    // also when another fix migrates atoms before this fix's pre_exchange
  int m = 0;
  buf[m++] = npartner[i];
  for (int k = 0; k < npartner[i]; k++) buf[m++] = ubuf(partner[i][k]).d;
  for (int k = 0; k < npartner[i] * dnum; k++) buf[m++] = values[i][k];
  for (int l = 0; l < JKRDT::NLEDGER; l++) buf[m++] = ledger[i][l];
  buf[m++] = ubuf(owner[i]).d;
  return m;
}

int FixJKRDTContacts::unpack_exchange(int nlocal, double *buf)
{
  int m = 0;
  const int n = static_cast<int>(buf[m++]);
  fresh(nlocal);
  reserve(nlocal, n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(buf[m++]).i;
  for (int k = 0; k < n * dnum; k++) values[nlocal][k] = buf[m++];
  for (int l = 0; l < JKRDT::NLEDGER; l++) ledger[nlocal][l] = buf[m++];
  owner[nlocal] = (tagint) ubuf(buf[m++]).i;
  return m;
}

/* ----------------------------------------------------------------------
   restart: size, layout mask, count, partner IDs, values, ledger, owner ID.
   The mask lets a run read a file written with other fields switched on.
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_restart(int i, double *buf)
{
  int m = 1;    // pack_exchange below writes the rows back first
  buf[m++] = mask;
  m += pack_exchange(i, &buf[m]);
  buf[0] = m;
  return m;
}

void FixJKRDTContacts::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);
  const double *record = extra[nlocal] + m;
  const double *buf = record + 1;

  const JKRDT::StateLayout file = JKRDT::state_layout(static_cast<int>(*buf++));
  const int filednum = file.dnum;
  const int n = static_cast<int>(*buf++);
  fresh(nlocal);
  reserve(nlocal, n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(*buf++).i;
  for (int k = 0; k < n; k++, buf += filednum) {
    if (!dnum) continue;
    JKRDT::relayout(buf, file, values[nlocal] + k * dnum, state);
  }
  // what follows: the ledger and the owner ID. Files written before the contacts made and
  // cut were counted hold the losses alone (their counts start at 0); files written before
  // the owner ID was stored end after the ledger: their IDs are the atoms' own
  const int rest = static_cast<int>(record[0]) - static_cast<int>(buf - record);
  const int nled = rest > JKRDT::NLOSS + 1 ? int(JKRDT::NLEDGER) : int(JKRDT::NLOSS);
  std::fill(ledger[nlocal], ledger[nlocal] + JKRDT::NLEDGER, 0.0);
  for (int l = 0; l < nled; l++) ledger[nlocal][l] = *buf++;
  const bool has_owner = rest > nled;
  owner[nlocal] = has_owner ? (tagint) ubuf(*buf).i : atom->tag[nlocal];
}

int FixJKRDTContacts::size_restart(int i)
{
  to_rows();    // a restart file written during a run: the rows take the state first
  return 4 + npartner[i] * (1 + dnum) + JKRDT::NLEDGER;
}

// called on every rank by write_restart, so it may reduce over ranks
int FixJKRDTContacts::maxsize_restart()
{
  to_rows();
  int nmine = 0, nall = 0;
  for (int i = 0; i < atom->nlocal; i++) nmine = std::max(nmine, npartner[i]);
  MPI_Allreduce(&nmine, &nall, 1, MPI_INT, MPI_MAX, world);
  return 4 + nall * (1 + dnum) + JKRDT::NLEDGER;    // as size_restart()
}

/* ----------------------------------------------------------------------
   restart, global part: the layout mask and the pair style's made_with. It is
   read before the atoms' records, so a file's fields all come back (the
   layout widened to them) for the pair style to book those it switched off
------------------------------------------------------------------------- */

void FixJKRDTContacts::write_restart(FILE *fp)
{
  std::vector<double> list = {static_cast<double>(mask), static_cast<double>(made_with.size())};
  list.insert(list.end(), made_with.begin(), made_with.end());
  if (comm->me == 0) {
    const int size = static_cast<int>(list.size() * sizeof(double));
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list.data(), sizeof(double), list.size(), fp);
  }
}

void FixJKRDTContacts::restart(char *buf)
{
  const auto *list = reinterpret_cast<const double *>(buf);
  const int filemask = static_cast<int>(list[0]);
  const auto n = static_cast<size_t>(list[1]);
  made_with.assign(list + 2, list + 2 + n);
  set_layout(mask | filemask);
}

/* ---------------------------------------------------------------------- */

double FixJKRDTContacts::memory_usage()
{
  const double nmax = nmax_alloc;
  return nmax * (2 * sizeof(int) + sizeof(tagint *) + sizeof(double *) +
                 JKRDT::NLEDGER * sizeof(double) + sizeof(tagint)) +
      (double) tag_arena.bytes() + (double) value_arena.bytes() +
      (double) maxslot * (1 + slot_dnum * sizeof(double)) + (double) maxfirst * sizeof(int);
}
