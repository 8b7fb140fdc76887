/* jkr/dt: coefficients, defaults and mixing of unlike types.

   pair_coeff I J keyword value ...
     gamma <surface energy>   E <Young's modulus>   nu <Poisson ratio>
     G <shear modulus>        xi_crit <length>       tvis <time>
     sliding on|off   rolling on|off   twisting on|off   frictionless
     damp_tension on|off   (off: no F_D of eq. A.5 while the contact is stretched, delta < 0)
     ks_scale <f>     kr_scale <f>     kt_scale <f>

   A type's own line (I = J) gives its material: gamma, E and nu are required,
   G defaults to E / (2 (1 + nu)). A line for unlike types (I != J) may set any
   keyword; what it leaves out is mixed from the two types' own lines:
     E*, G*   eqs. (2) and (13) from each type's E, nu, G
     gamma    geometric mean sqrt(gamma_I gamma_J)   (work of adhesion 2 sqrt(gamma_I gamma_J))
     nu       (in the damping of eq. A.5) arithmetic mean
     xi_crit, tvis, scale factors  arithmetic mean
     channels on only where both types have them on
   A scale factor multiplies its stiffness (k_s, k_r, k_t) and keeps the
   critical displacement, so the critical force or torque, and E_roll,
   scale with it.
   E, nu and G given on an unlike line are taken as the material of both
   particles of that pair.                                                   */

#include "pair_jkr_dt.h"

#include "jkr_dt_normal.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "modify.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using namespace LAMMPS_NS;

static constexpr double UNSET = std::numeric_limits<double>::quiet_NaN();
using Key = PairJKRDT::Key;

/* ----------------------------------------------------------------------
   the pair_coeff keywords: one row each drives the parsing, the error
   messages, the mixing of unlike types, data files and restart files
   (which name their keywords, so a file written before a keyword was added
   reads back with that keyword unset)
------------------------------------------------------------------------- */

namespace {
enum class Value { POSITIVE, POISSON, NONNEGATIVE, SWITCH };
enum class Mix {
  MATERIAL,     // E, nu, G: each side's own, into eqs. (2), (13) and (A.5)
  GEOMETRIC,    // sqrt(a b)
  MEAN,         // (a + b) / 2, unset if either is
  MEAN_OR_0,    // (a + b) / 2, an unset side counts 0
  MEAN_OR_1,    // (a + b) / 2, an unset side counts 1
  BOTH_ON       // on where both sides are (unset counts as on)
};
struct Keyword {
  Key key;
  const char *name;
  Value value;
  Mix mix;
};
constexpr Keyword KEYWORDS[PairJKRDT::NKEY] = {
    {PairJKRDT::GAMMA, "gamma", Value::POSITIVE, Mix::GEOMETRIC},
    {PairJKRDT::E, "E", Value::POSITIVE, Mix::MATERIAL},
    {PairJKRDT::NU, "nu", Value::POISSON, Mix::MATERIAL},
    {PairJKRDT::G, "G", Value::POSITIVE, Mix::MATERIAL},
    {PairJKRDT::XI_CRIT, "xi_crit", Value::POSITIVE, Mix::MEAN},
    {PairJKRDT::TVIS, "tvis", Value::NONNEGATIVE, Mix::MEAN_OR_0},
    {PairJKRDT::KS_SCALE, "ks_scale", Value::POSITIVE, Mix::MEAN_OR_1},
    {PairJKRDT::KR_SCALE, "kr_scale", Value::POSITIVE, Mix::MEAN_OR_1},
    {PairJKRDT::KT_SCALE, "kt_scale", Value::POSITIVE, Mix::MEAN_OR_1},
    {PairJKRDT::SLIDING, "sliding", Value::SWITCH, Mix::BOTH_ON},
    {PairJKRDT::ROLLING, "rolling", Value::SWITCH, Mix::BOTH_ON},
    {PairJKRDT::TWISTING, "twisting", Value::SWITCH, Mix::BOTH_ON},
    {PairJKRDT::DAMP_TENSION, "damp_tension", Value::SWITCH, Mix::BOTH_ON},
};
// keywords that are not values of a type pair
constexpr const char *FRICTIONLESS = "frictionless";     // sliding, rolling, twisting off
constexpr const char *DATA_CONTACTS = "data_contacts";   // write_data's mark

// the table is indexed by its keys (resolve() reads KEYWORDS[key])
constexpr bool in_key_order()
{
  for (int k = 0; k < PairJKRDT::NKEY; k++)
    if (KEYWORDS[k].key != k) return false;
  return true;
}
static_assert(in_key_order(), "KEYWORDS must list the keys in the order of PairJKRDT::Key");

const Keyword *keyword(const std::string &word)
{
  for (const Keyword &k : KEYWORDS)
    if (word == k.name) return &k;
  return nullptr;
}

// any word of a pair_coeff line that is not a value
bool is_keyword(const std::string &word)
{
  return keyword(word) || word == FRICTIONLESS || word == DATA_CONTACTS;
}

std::string keyword_list()
{
  std::string all;
  for (const Keyword &k : KEYWORDS) all += std::string(k.name) + " ";
  return all + FRICTIONLESS;
}

PairJKRDT::Input nothing_given()
{
  PairJKRDT::Input g;
  std::fill(g.v, g.v + PairJKRDT::NKEY, UNSET);
  return g;
}
}    // namespace

/* ---------------------------------------------------------------------- */

void PairJKRDT::settings(int narg, char **arg)
{
  // pair_style jkr/dt [dt_check error|warn|off] [bins bounded|box] [kernel auto|portable]
  //                   [lean yes|no]
  dt_check = DT_CHECK_ERROR;
  bins_bounded = true;
  kernel_auto = true;
  lean_enabled = true;
  data_contacts = 0;    // the deliberate fresh start from a marked data file
  if (fix_contacts && !modify->get_fix_by_id(FIX_ID)) {    // given anew after an unfix
    fix_contacts = nullptr;
    contacts_at_run_end = 0;
  }
  for (int iarg = 0; iarg < narg; iarg += 2) {
    const std::string key = arg[iarg];
    const std::string value = (iarg + 1 < narg) ? arg[iarg + 1] : "";
    if (key == "dt_check") {
      if (value == "error") dt_check = DT_CHECK_ERROR;
      else if (value == "warn") dt_check = DT_CHECK_WARN;
      else if (value == "off") dt_check = DT_CHECK_OFF;
      else
        error->all(FLERR, "pair_style jkr/dt: dt_check takes error, warn or off (got '{}')",
                   value);
    } else if (key == "bins") {
      if (value == "bounded") bins_bounded = true;
      else if (value == "box") bins_bounded = false;
      else
        error->all(FLERR, "pair_style jkr/dt: bins takes bounded or box (got '{}')", value);
    } else if (key == "kernel") {
      if (value == "auto") kernel_auto = true;
      else if (value == "portable") kernel_auto = false;
      else
        error->all(FLERR, "pair_style jkr/dt: kernel takes auto or portable (got '{}')", value);
    } else if (key == "lean") {
      if (value == "yes") lean_enabled = true;
      else if (value == "no") lean_enabled = false;
      else
        error->all(FLERR, "pair_style jkr/dt: lean takes yes or no (got '{}')", value);
    } else {
      error->all(FLERR,
                 "pair_style jkr/dt: unknown setting '{}'; the settings are 'dt_check "
                 "error|warn|off', 'bins bounded|box', 'kernel auto|portable' and 'lean "
                 "yes|no' (material parameters go in pair_coeff)",
                 key);
    }
  }
}

/* ---------------------------------------------------------------------- */

void PairJKRDT::allocate()
{
  allocated = 1;
  const int n = atom->ntypes;
  nstride = n + 1;
  memory->create(setflag, n + 1, n + 1, "pair:setflag");
  memory->create(cutsq, n + 1, n + 1, "pair:cutsq");
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++) setflag[i][j] = 0;
  input.assign(nstride * nstride, nothing_given());
  param.assign(nstride * nstride, Param());
  maxrad.assign(nstride, 0.0);
}

/* ---------------------------------------------------------------------- */

void PairJKRDT::coeff(int narg, char **arg)
{
  if (narg < 2) error->all(FLERR, "pair_coeff for jkr/dt: expected 'pair_coeff I J keyword value ...'");
  if (!allocated) allocate();

  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);

  Input g = nothing_given();
  bigint marked = 0;
  int iarg = 2;
  auto value = [&](const std::string &key) -> const char * {
    if (iarg + 1 >= narg || is_keyword(arg[iarg + 1]))
      error->all(FLERR, "pair_coeff for jkr/dt: keyword '{}' needs a value{}", key,
                 iarg + 1 < narg ? fmt::format(" (next is the keyword '{}')", arg[iarg + 1])
                                 : std::string(" (the line ends)"));
    return arg[iarg + 1];
  };
  auto read = [&](const Keyword &k) -> double {
    if (k.value == Value::SWITCH) {
      const std::string word = value(k.name);
      if (word == "on" || word == "yes" || word == "true") return 1.0;
      if (word == "off" || word == "no" || word == "false") return 0.0;
      error->all(FLERR, "pair_coeff for jkr/dt: {} takes on or off (got '{}')", k.name, word);
    }
    const double x = utils::numeric(FLERR, value(k.name), false, lmp);
    if (k.value == Value::POSITIVE && !(x > 0.0))
      error->all(FLERR, "pair_coeff for jkr/dt: {} must be > 0 (got {})", k.name, x);
    if (k.value == Value::POISSON && !(x > -1.0 && x < 0.5))
      error->all(FLERR, "pair_coeff for jkr/dt: {} must lie in (-1, 0.5) (got {})", k.name, x);
    if (k.value == Value::NONNEGATIVE && !(x >= 0.0))
      error->all(FLERR, "pair_coeff for jkr/dt: {} must be >= 0; 0 means none (got {})", k.name,
                 x);
    return x;
  };

  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (const Keyword *k = keyword(key)) {
      g.v[k->key] = read(*k);
    } else if (key == FRICTIONLESS) {
      g.v[SLIDING] = g.v[ROLLING] = g.v[TWISTING] = 0.0;
      iarg += 1;
      continue;
    } else if (key == DATA_CONTACTS) {
      marked = utils::bnumeric(FLERR, value(key), false, lmp);    // written by write_data
    } else {
      error->all(FLERR, "pair_coeff for jkr/dt: unknown keyword '{}'; allowed: {}", key,
                 keyword_list());
    }
    iarg += 2;
  }

  if (g.given(E) != g.given(NU))
    error->all(FLERR, "pair_coeff for jkr/dt: E and nu go together; give both or neither");
  if (g.given(G) && !g.given(E))
    error->all(FLERR, "pair_coeff for jkr/dt: G needs E and nu on the same line");

  int count = 0;
  for (int i = ilo; i <= ihi; i++)
    for (int j = std::max(jlo, i); j <= jhi; j++) {
      if (i == j && !(g.given(GAMMA) && g.given(E))) {
        std::string missing = g.given(GAMMA) ? "" : "gamma";
        if (!g.given(E)) missing += missing.empty() ? "E and nu" : ", E and nu";
        error->all(FLERR,
                   "pair_coeff {} {} for jkr/dt: a type's own line must give its material; "
                   "missing: {}",
                   i, j, missing);
      }
      in(i, j) = g;
      setflag[i][j] = 1;
      count++;
    }
  if (count == 0) error->all(FLERR, "pair_coeff for jkr/dt: no type pair matched {} {}", arg[0], arg[1]);
  // a data file's mark stays through later pair_coeff commands (decks give their own after
  // read_data); only pair_style jkr/dt given anew clears it
  data_contacts = std::max(data_contacts, marked);
}

/* ----------------------------------------------------------------------
   defaults and mixing for type pair (i,j); errors name the missing piece
------------------------------------------------------------------------- */

PairJKRDT::Param PairJKRDT::resolve(int i, int j) const
{
  const Input &ij = in(i, j), &ii = in(i, i), &jj = in(j, j);
  const bool own = setflag[i][j] != 0;

  // a keyword's value for the pair: its own line's if given, else mixed by the table
  auto mixed = [&](Key key) {
    if (own && ij.given(key)) return ij.v[key];
    const double a = ii.v[key], b = jj.v[key];
    switch (KEYWORDS[key].mix) {
      case Mix::GEOMETRIC: return std::sqrt(a * b);
      case Mix::MEAN: return 0.5 * (a + b);
      case Mix::MEAN_OR_0: return 0.5 * ((a == a ? a : 0.0) + (b == b ? b : 0.0));
      case Mix::MEAN_OR_1: return 0.5 * ((a == a ? a : 1.0) + (b == b ? b : 1.0));
      case Mix::BOTH_ON: return (a != 0.0 && b != 0.0) ? 1.0 : 0.0;    // unset (NaN) is on
      case Mix::MATERIAL: break;
    }
    return UNSET;
  };

  // material of the two sides (Mix::MATERIAL): the pair's own line if it gives one, else
  // each type's
  const Input &m1 = (own && ij.given(E)) ? ij : ii;
  const Input &m2 = (own && ij.given(E)) ? ij : jj;
  auto shear = [](const Input &m) {
    return m.given(G) ? m.v[G] : m.v[E] / (2.0 * (1.0 + m.v[NU]));
  };
  const double nu1 = m1.v[NU], nu2 = m2.v[NU];

  Param P;
  P.Estar = 1.0 / ((1.0 - nu1 * nu1) / m1.v[E] + (1.0 - nu2 * nu2) / m2.v[E]);    // eq. (2)
  P.Gstar = 1.0 / ((2.0 - nu1) / shear(m1) + (2.0 - nu2) / shear(m2));          // eq. (13)
  P.Gred = 1.0 / (1.0 / shear(m1) + 1.0 / shear(m2));                           // below eq. (26)
  P.nu = 0.5 * (nu1 + nu2);

  P.gamma = mixed(GAMMA);
  P.xi_crit = mixed(XI_CRIT);
  P.tvis = mixed(TVIS);
  const double ks_scale = mixed(KS_SCALE), kr_scale = mixed(KR_SCALE);
  const double kt_scale = mixed(KT_SCALE);
  P.sliding = mixed(SLIDING) != 0.0;
  P.rolling = mixed(ROLLING) != 0.0;
  P.twisting = mixed(TWISTING) != 0.0;
  P.damp_tension = mixed(DAMP_TENSION) != 0.0;
  // in 2D omega lies along z and n_c in the plane: the twisting angle of eq. (24) stays 0,
  // so the channel is off and its angle is not stored
  if (domain->dimension == 2) P.twisting = 0;

  if (P.rolling && std::isnan(P.xi_crit))
    error->all(FLERR,
               "pair jkr/dt: rolling is on for types {} {} but xi_crit is not set; give "
               "'xi_crit <length>' (the papers use 2, 8 or 30 Angstrom) or 'rolling off' or "
               "'frictionless'",
               i, j);
  if (P.tvis > 0.0 && P.nu == 0.0)
    error->all(FLERR,
               "pair jkr/dt: types {} {} have tvis > 0 but nu = 0; the damping of eq. (A.5) "
               "divides by nu^2",
               i, j);

  P.a0_coef = JKRDT::a0_coefficient(P.gamma, P.Estar);
  P.damp_coef = (P.tvis > 0.0) ? JKRDT::damping_coefficient(P.tvis, P.Estar, P.nu) : 0.0;
  P.ks_coef = 8.0 * P.Gstar * ks_scale;                          // eq. (12)
  P.zeta_coef = P.Gred / (16.0 * JKRDT::PI * P.Gstar);          // eqs. (35)-(36)
  P.k_r = 12.0 * JKRDT::PI * P.gamma * kr_scale;                // eq. (22): 4 F_c / R
  P.kt_coef = (16.0 / 3.0) * P.Gred * kt_scale;                 // eq. (26)

  // a stretched contact reaches r1 + r2 + delta_c; delta_c grows with R as R^(1/3)
  const double r1 = maxrad[i], r2 = maxrad[j];
  P.cut = 0.0;
  if (r1 > 0.0 && r2 > 0.0) P.cut = r1 + r2 + JKRDT::normal_scales(r1, r2, P.gamma, P.a0_coef).delta_c;
  return P;
}

/* ---------------------------------------------------------------------- */

double PairJKRDT::init_one(int i, int j)
{
  // parameters were resolved, for (i,j) and (j,i) alike, in init_style()
  return par(i, j).cut;
}

/* ----------------------------------------------------------------------
   restart and data files carry what the user gave, not the mixed values,
   so a continued run mixes exactly as the first one did
------------------------------------------------------------------------- */

// a restart file's coefficients: NAMED, then the keywords by name, then each type pair's
// setflag and, if set, one double per keyword in that order. A file of the first builds
// (positional: 9 doubles and 3 ints, no names) starts with the first setflag instead
static constexpr int NAMED = -2;
static constexpr int NLEGACY = 12;
static constexpr int LEGACY_ORDER[NLEGACY] = {
    PairJKRDT::GAMMA,    PairJKRDT::E,        PairJKRDT::NU,       PairJKRDT::G,
    PairJKRDT::XI_CRIT,  PairJKRDT::TVIS,     PairJKRDT::KS_SCALE, PairJKRDT::KR_SCALE,
    PairJKRDT::KT_SCALE, PairJKRDT::SLIDING,  PairJKRDT::ROLLING,  PairJKRDT::TWISTING};

void PairJKRDT::write_restart(FILE *fp)
{
  const int head[2] = {NAMED, NKEY};
  fwrite(head, sizeof(int), 2, fp);
  for (const Keyword &k : KEYWORDS) {
    const int length = (int) std::strlen(k.name);
    fwrite(&length, sizeof(int), 1, fp);
    fwrite(k.name, 1, length, fp);
  }
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fwrite(&setflag[i][j], sizeof(int), 1, fp);
      if (setflag[i][j]) fwrite(in(i, j).v, sizeof(double), NKEY, fp);
    }
}

void PairJKRDT::read_restart(FILE *fp)
{
  allocate();
  const int me = comm->me;
  auto read_ints = [&](int *x, int n) {
    if (me == 0) utils::sfread(FLERR, x, sizeof(int), n, fp, nullptr, error);
    MPI_Bcast(x, n, MPI_INT, 0, world);
  };
  auto read_doubles = [&](double *x, int n) {
    if (me == 0) utils::sfread(FLERR, x, sizeof(double), n, fp, nullptr, error);
    MPI_Bcast(x, n, MPI_DOUBLE, 0, world);
  };
  int first;
  read_ints(&first, 1);
  std::vector<int> order;    // the file's keywords, as keys of this build
  if (first == NAMED) {
    int count;
    read_ints(&count, 1);
    for (int n = 0; n < count; n++) {
      int length;
      read_ints(&length, 1);
      std::string name(length, ' ');
      if (me == 0) utils::sfread(FLERR, &name[0], 1, length, fp, nullptr, error);
      MPI_Bcast(&name[0], length, MPI_CHAR, 0, world);
      const Keyword *k = keyword(name);
      if (!k)
        error->all(FLERR,
                   "pair jkr/dt: the restart file has the pair_coeff keyword '{}', which this "
                   "build does not know; read it with the build that wrote it, or give "
                   "pair_coeff anew after read_restart",
                   name);
      order.push_back(k->key);
    }
  } else {
    order.assign(LEGACY_ORDER, LEGACY_ORDER + NLEGACY);
  }
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (i == 1 && j == 1 && first != NAMED)
        setflag[i][j] = first;
      else
        read_ints(&setflag[i][j], 1);
      if (!setflag[i][j]) continue;
      Input &g = in(i, j);
      g = nothing_given();
      if (first == NAMED) {
        std::vector<double> v(order.size());
        read_doubles(v.data(), (int) v.size());
        for (size_t n = 0; n < order.size(); n++) g.v[order[n]] = v[n];
      } else {
        double d[9];
        int k[3];
        read_doubles(d, 9);
        read_ints(k, 3);
        for (int n = 0; n < 9; n++) g.v[order[n]] = d[n];
        for (int n = 0; n < 3; n++) g.v[order[9 + n]] = k[n] < 0 ? UNSET : k[n];
      }
    }
}

/* ----------------------------------------------------------------------
   data files: "Pair Coeffs" (write_data's default) holds each type's own
   line, "PairIJ Coeffs" (write_data ... pair ij) every line given; a file
   written after a run is marked with the contacts it cannot carry
------------------------------------------------------------------------- */

std::string PairJKRDT::coeff_words(const Input &g) const
{
  std::string line;
  for (const Keyword &k : KEYWORDS) {
    if (!g.given(k.key)) continue;
    if (k.value == Value::SWITCH)
      line += fmt::format(" {} {}", k.name, g.v[k.key] != 0.0 ? "on" : "off");
    else
      line += fmt::format(" {} {:.17g}", k.name, g.v[k.key]);
  }
  if (contacts_at_run_end > 0)
    line += fmt::format(" {} {}", DATA_CONTACTS, contacts_at_run_end);
  return line;
}

void PairJKRDT::warn_data_file() const
{
  if (contacts_at_run_end > 0)
    error->warning(FLERR,
                   "pair jkr/dt: write_data does not carry the {} bonded contacts (pointers, "
                   "twist, damping force, energy ledger); a run read from this file refuses to "
                   "start. To continue a run, use write_restart / read_restart",
                   contacts_at_run_end);
}

void PairJKRDT::write_data(FILE *fp)
{
  warn_data_file();
  for (int i = 1; i <= atom->ntypes; i++)
    if (setflag[i][i]) fmt::print(fp, "{}{}\n", i, coeff_words(in(i, i)));
}

void PairJKRDT::write_data_all(FILE *fp)
{
  warn_data_file();
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++)
      if (setflag[i][j]) fmt::print(fp, "{} {}{}\n", i, j, coeff_words(in(i, j)));
}
