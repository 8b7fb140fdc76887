/* jkr/dt: per-contact state storage. See fix_jkr_dt_contacts.h. */

#include "fix_jkr_dt_contacts.h"

#include "pair_jkr_dt.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>
#include <cstring>

using namespace LAMMPS_NS;

static constexpr int INITIAL_CAPACITY = 8;

/* ---------------------------------------------------------------------- */

FixJKRDTContacts::FixJKRDTContacts(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), npartner(nullptr), partner(nullptr), values(nullptr), ledger(nullptr),
    owner(nullptr), dnum(0), natoms_at_run_end(0), mask(0), maxpartner(INITIAL_CAPACITY), nmax_alloc(0)
{
  if (narg != 4)
    error->all(FLERR,
               "fix jkr/dt/contacts is created by pair_style jkr/dt; do not define it by hand");
  mask = utils::inumeric(FLERR, arg[3], false, lmp);
  dnum = layout_size(mask, field_offset);

  restart_peratom = 1;
  create_attribute = 1;
  peratom_flag = 1;
  size_peratom_cols = NLEDGER;
  peratom_freq = 1;
  scalar_flag = 1;
  global_freq = 1;
  extscalar = 0;

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
  memory->destroy(partner);
  memory->destroy(values);
  memory->destroy(ledger);
  memory->destroy(owner);
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
  int changed[2] = {moved, natoms_before > 0 && atom->natoms < natoms_before};
  int any[2] = {0, 0};
  MPI_Allreduce(changed, any, 2, MPI_INT, MPI_MAX, world);
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

  const int off_n = has_field(POINTERS) ? offset(POINTERS) : -1;
  bigint counts[2] = {0, 0}, all[2] = {0, 0};    // contacts removed, atoms renamed
  for (int i = 0; i < nlocal; i++) {
    if (npartner[i] > 0 && owner[i] != tag[i]) counts[1]++;
    for (int k = npartner[i] - 1; k >= 0; k--) {
      const tagint was = partner[i][k];
      auto it = std::lower_bound(renamed.begin(), renamed.end(),
                                 std::make_pair(was, std::numeric_limits<tagint>::min()));
      if (it == renamed.end() || it->first != was) {    // the partner is gone
        remove(i, k);
        counts[0]++;
        continue;
      }
      const tagint now = it->second;
      if (off_n >= 0 && (owner[i] < was) != (tag[i] < now)) {
        double *n = contact_values(i, k) + off_n;
        std::swap_ranges(n, n + 3, n + 3);
      }
      partner[i][k] = now;
    }
    owner[i] = tag[i];
  }
  MPI_Allreduce(counts, all, 2, MPI_LMP_BIGINT, MPI_SUM, world);
  if (all[0] && !any[1])
    error->all(FLERR,
               "pair jkr/dt: {} stored contacts point at atoms that no longer store them, "
               "though no atom was deleted: the contact state is inconsistent",
               all[0]);
  if (comm->me == 0) {
    if (all[0]) utils::logmesg(lmp, "pair jkr/dt: {} contacts with deleted atoms removed\n", all[0]);
    if (all[1])
      utils::logmesg(lmp, "pair jkr/dt: the contacts of {} renumbered atoms follow their new IDs\n",
                     all[1]);
  }
}

/* ----------------------------------------------------------------------
   a run without pair jkr/dt would move the atoms under stored contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::init()
{
  if (force->pair_match("jkr/dt", 1, 0)) return;
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

std::vector<tagint> FixJKRDTContacts::gather(const std::vector<tagint> &mine, MPI_Comm world)
{
  int nprocs = 1;
  MPI_Comm_size(world, &nprocs);
  const int n = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int r = 1; r < nprocs; r++) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<tagint> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_LMP_TAGINT, all.data(), counts.data(), displs.data(),
                 MPI_LMP_TAGINT, world);
  return all;
}

/* ----------------------------------------------------------------------
   end of a run: the pair style reports how well the step resolved contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::post_run()
{
  auto *pair = dynamic_cast<PairJKRDT *>(force->pair_match("jkr/dt", 1, 0));
  if (pair) pair->report_run();
}

/* ----------------------------------------------------------------------
   offsets of the fields present in a layout mask; returns doubles per contact
------------------------------------------------------------------------- */

int FixJKRDTContacts::layout_size(int layout, int *offsets)
{
  int n = 0;
  for (int f = 0; f < NFIELD; f++) {
    offsets[f] = -1;
    if ((layout >> f) & 1) {
      offsets[f] = n;
      n += FIELD_SIZE[f];
    }
  }
  return n;
}

/* ----------------------------------------------------------------------
   switch to a new set of fields, keeping the values of fields in both
------------------------------------------------------------------------- */

void FixJKRDTContacts::set_layout(int newmask)
{
  if (newmask == mask) return;
  int newoffset[NFIELD];
  const int newdnum = layout_size(newmask, newoffset);
  const int nmax = nmax_alloc;

  double **newvalues = nullptr;
  if (newdnum > 0) memory->create(newvalues, nmax, maxpartner * newdnum, "jkr/dt:values");
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < npartner[i]; k++) {
      double *dst = newvalues ? newvalues[i] + k * newdnum : nullptr;
      if (dst) std::fill(dst, dst + newdnum, 0.0);
      for (int f = 0; f < NFIELD; f++)
        if (newoffset[f] >= 0 && field_offset[f] >= 0)
          std::copy_n(values[i] + k * dnum + field_offset[f], FIELD_SIZE[f], dst + newoffset[f]);
    }
  memory->destroy(values);
  values = newvalues;
  mask = newmask;
  dnum = newdnum;
  std::copy_n(newoffset, NFIELD, field_offset);
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
  if (npartner[i] == maxpartner) grow_partner_capacity(maxpartner + 1);
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
   a rank's per-atom capacity grows whenever one atom needs more room;
   it never drops a contact
------------------------------------------------------------------------- */

void FixJKRDTContacts::grow_partner_capacity(int needed)
{
  if (needed <= maxpartner) return;
  const int newmax = std::max(needed, maxpartner + maxpartner / 2);
  const int nmax = nmax_alloc;

  tagint **newpartner = nullptr;
  double **newvalues = nullptr;
  memory->create(newpartner, nmax, newmax, "jkr/dt:partner");
  if (dnum) memory->create(newvalues, nmax, newmax * dnum, "jkr/dt:values");
  for (int i = 0; i < nmax; i++) {
    std::copy_n(partner[i], npartner[i], newpartner[i]);
    if (dnum) std::copy_n(values[i], npartner[i] * dnum, newvalues[i]);
  }
  memory->destroy(partner);
  memory->destroy(values);
  partner = newpartner;
  values = newvalues;
  maxpartner = newmax;
}

/* ----------------------------------------------------------------------
   per-atom callbacks: growth, copy (sorting, deletion), new atoms
------------------------------------------------------------------------- */

void FixJKRDTContacts::grow_arrays(int nmax)
{
  const int oldmax = nmax_alloc;
  memory->grow(npartner, nmax, "jkr/dt:npartner");
  memory->grow(partner, nmax, maxpartner, "jkr/dt:partner");
  if (dnum) memory->grow(values, nmax, maxpartner * dnum, "jkr/dt:values");
  memory->grow(ledger, nmax, NLEDGER, "jkr/dt:ledger");
  memory->grow(owner, nmax, "jkr/dt:owner");
  nmax_alloc = nmax;
  for (int i = oldmax; i < nmax; i++) set_arrays(i);
  array_atom = ledger;
}

void FixJKRDTContacts::copy_arrays(int i, int j, int /*delflag*/)
{
  npartner[j] = npartner[i];
  std::copy_n(partner[i], npartner[i], partner[j]);
  if (dnum) std::copy_n(values[i], npartner[i] * dnum, values[j]);
  std::copy_n(ledger[i], (int) NLEDGER, ledger[j]);
  owner[j] = owner[i];
}

void FixJKRDTContacts::set_arrays(int i)
{
  npartner[i] = 0;
  owner[i] = 0;
  std::fill(ledger[i], ledger[i] + NLEDGER, 0.0);
}

/* ----------------------------------------------------------------------
   migration between ranks: count, partner IDs, values, ledger, owner ID
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_exchange(int i, double *buf)
{
  int m = 0;
  buf[m++] = npartner[i];
  for (int k = 0; k < npartner[i]; k++) buf[m++] = ubuf(partner[i][k]).d;
  for (int k = 0; k < npartner[i] * dnum; k++) buf[m++] = values[i][k];
  for (int l = 0; l < NLEDGER; l++) buf[m++] = ledger[i][l];
  buf[m++] = ubuf(owner[i]).d;
  return m;
}

int FixJKRDTContacts::unpack_exchange(int nlocal, double *buf)
{
  int m = 0;
  const int n = static_cast<int>(buf[m++]);
  grow_partner_capacity(n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(buf[m++]).i;
  for (int k = 0; k < n * dnum; k++) values[nlocal][k] = buf[m++];
  for (int l = 0; l < NLEDGER; l++) ledger[nlocal][l] = buf[m++];
  owner[nlocal] = (tagint) ubuf(buf[m++]).i;
  return m;
}

/* ----------------------------------------------------------------------
   restart: size, layout mask, count, partner IDs, values, ledger, owner ID.
   The mask lets a run read a file written with other fields switched on.
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_restart(int i, double *buf)
{
  int m = 1;
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

  const int filemask = static_cast<int>(*buf++);
  int fileoffset[NFIELD];
  const int filednum = layout_size(filemask, fileoffset);
  const int n = static_cast<int>(*buf++);
  grow_partner_capacity(n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(*buf++).i;
  for (int k = 0; k < n; k++, buf += filednum) {
    if (!dnum) continue;
    double *dst = values[nlocal] + k * dnum;
    std::fill(dst, dst + dnum, 0.0);
    for (int f = 0; f < NFIELD; f++)
      if (field_offset[f] >= 0 && fileoffset[f] >= 0)
        std::copy_n(buf + fileoffset[f], FIELD_SIZE[f], dst + field_offset[f]);
  }
  for (int l = 0; l < NLEDGER; l++) ledger[nlocal][l] = *buf++;
  // files written before the owner ID was stored end here: their IDs are the atoms' own
  const bool has_owner = buf - record < static_cast<int>(record[0]);
  owner[nlocal] = has_owner ? (tagint) ubuf(*buf).i : atom->tag[nlocal];
}

int FixJKRDTContacts::size_restart(int i)
{
  return 4 + npartner[i] * (1 + dnum) + NLEDGER;
}

// called on every rank by write_restart, so it may reduce over ranks
int FixJKRDTContacts::maxsize_restart()
{
  int nmine = 0, nall = 0;
  for (int i = 0; i < atom->nlocal; i++) nmine = std::max(nmine, npartner[i]);
  MPI_Allreduce(&nmine, &nall, 1, MPI_INT, MPI_MAX, world);
  return 4 + nall * (1 + dnum) + NLEDGER;    // as size_restart()
}

/* ---------------------------------------------------------------------- */

double FixJKRDTContacts::memory_usage()
{
  const double nmax = nmax_alloc;
  return nmax *
      (sizeof(int) + maxpartner * (sizeof(tagint) + dnum * sizeof(double)) +
       NLEDGER * sizeof(double));
}
