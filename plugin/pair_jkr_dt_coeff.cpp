/* jkr/dt: coefficients, defaults and mixing of unlike types.

   pair_coeff I J keyword value ...
     gamma <surface energy>   E <Young's modulus>   nu <Poisson ratio>
     G <shear modulus>        xi_crit <length>       tvis <time>
     sliding on|off   rolling on|off   twisting on|off   frictionless
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
#include <limits>
#include <string>
#include <vector>

using namespace LAMMPS_NS;

static constexpr double UNSET = std::numeric_limits<double>::quiet_NaN();
static const PairJKRDT::Input NOTHING_GIVEN = {UNSET, UNSET, UNSET, UNSET, UNSET, UNSET,
                                               UNSET, UNSET, UNSET, -1,    -1,    -1};

static bool given(double x) { return !std::isnan(x); }

/* ---------------------------------------------------------------------- */

void PairJKRDT::settings(int narg, char **arg)
{
  // pair_style jkr/dt [dt_check error|warn|off] [bins bounded|box]
  dt_check = DT_CHECK_ERROR;
  bins_bounded = true;
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
    } else {
      error->all(FLERR,
                 "pair_style jkr/dt: unknown setting '{}'; the settings are 'dt_check "
                 "error|warn|off' and 'bins bounded|box' (material parameters go in pair_coeff)",
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
  input.assign(nstride * nstride, NOTHING_GIVEN);
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

  Input g = NOTHING_GIVEN;
  bigint marked = 0;
  int iarg = 2;
  static const std::vector<std::string> keywords = {
      "gamma",   "E",       "nu",       "G",        "xi_crit",  "tvis",    "sliding",
      "rolling", "twisting", "frictionless", "ks_scale", "kr_scale", "kt_scale", "data_contacts"};
  auto is_keyword = [&](const char *word) {
    return std::find(keywords.begin(), keywords.end(), word) != keywords.end();
  };
  auto value = [&](const std::string &key) -> const char * {
    if (iarg + 1 >= narg || is_keyword(arg[iarg + 1]))
      error->all(FLERR, "pair_coeff for jkr/dt: keyword '{}' needs a value{}", key,
                 iarg + 1 < narg ? fmt::format(" (next is the keyword '{}')", arg[iarg + 1])
                                 : std::string(" (the line ends)"));
    return arg[iarg + 1];
  };
  auto on_off = [&](const std::string &key) {
    const std::string word = value(key);
    if (word == "on" || word == "yes" || word == "true") return 1;
    if (word == "off" || word == "no" || word == "false") return 0;
    error->all(FLERR, "pair_coeff for jkr/dt: {} takes on or off (got '{}')", key, word);
    return 0;
  };
  auto positive = [&](const std::string &key) {
    const double x = utils::numeric(FLERR, value(key), false, lmp);
    if (!(x > 0.0)) error->all(FLERR, "pair_coeff for jkr/dt: {} must be > 0 (got {})", key, x);
    return x;
  };

  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "gamma") {
      g.gamma = positive(key);
    } else if (key == "E") {
      g.E = positive(key);
    } else if (key == "G") {
      g.G = positive(key);
    } else if (key == "xi_crit") {
      g.xi_crit = positive(key);
    } else if (key == "ks_scale") {
      g.ks_scale = positive(key);
    } else if (key == "kr_scale") {
      g.kr_scale = positive(key);
    } else if (key == "kt_scale") {
      g.kt_scale = positive(key);
    } else if (key == "nu") {
      g.nu = utils::numeric(FLERR, value(key), false, lmp);
      if (!(g.nu > -1.0 && g.nu < 0.5))
        error->all(FLERR, "pair_coeff for jkr/dt: nu must lie in (-1, 0.5) (got {})", g.nu);
    } else if (key == "tvis") {
      g.tvis = utils::numeric(FLERR, value(key), false, lmp);
      if (!(g.tvis >= 0.0))
        error->all(FLERR, "pair_coeff for jkr/dt: tvis must be >= 0; 0 means no damping (got {})",
                   g.tvis);
    } else if (key == "sliding") {
      g.sliding = on_off(key);
    } else if (key == "rolling") {
      g.rolling = on_off(key);
    } else if (key == "twisting") {
      g.twisting = on_off(key);
    } else if (key == "frictionless") {
      g.sliding = g.rolling = g.twisting = 0;
      iarg += 1;
      continue;
    } else if (key == "data_contacts") {
      marked = utils::bnumeric(FLERR, value(key), false, lmp);    // written by write_data
    } else {
      error->all(FLERR,
                 "pair_coeff for jkr/dt: unknown keyword '{}'; allowed: gamma E nu G xi_crit "
                 "tvis sliding rolling twisting frictionless ks_scale kr_scale kt_scale",
                 key);
    }
    iarg += 2;
  }

  if (given(g.E) != given(g.nu))
    error->all(FLERR, "pair_coeff for jkr/dt: E and nu go together; give both or neither");
  if (given(g.G) && !given(g.E))
    error->all(FLERR, "pair_coeff for jkr/dt: G needs E and nu on the same line");

  int count = 0;
  for (int i = ilo; i <= ihi; i++)
    for (int j = std::max(jlo, i); j <= jhi; j++) {
      if (i == j && !(given(g.gamma) && given(g.E))) {
        std::string missing = given(g.gamma) ? "" : "gamma";
        if (!given(g.E)) missing += missing.empty() ? "E and nu" : ", E and nu";
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

  // material of the two sides: the pair's own line if it gives one, else each type's
  const Input &m1 = (own && given(ij.E)) ? ij : ii;
  const Input &m2 = (own && given(ij.E)) ? ij : jj;
  auto shear = [](const Input &m) { return given(m.G) ? m.G : m.E / (2.0 * (1.0 + m.nu)); };

  Param P;
  P.Estar = 1.0 / ((1.0 - m1.nu * m1.nu) / m1.E + (1.0 - m2.nu * m2.nu) / m2.E);    // eq. (2)
  P.Gstar = 1.0 / ((2.0 - m1.nu) / shear(m1) + (2.0 - m2.nu) / shear(m2));          // eq. (13)
  P.Gred = 1.0 / (1.0 / shear(m1) + 1.0 / shear(m2));                               // below eq. (26)
  P.nu = 0.5 * (m1.nu + m2.nu);

  auto mean = [](double a, double b) { return 0.5 * (a + b); };
  auto zero_if_unset = [](double x) { return given(x) ? x : 0.0; };
  P.gamma = (own && given(ij.gamma)) ? ij.gamma : std::sqrt(ii.gamma * jj.gamma);
  P.xi_crit = (own && given(ij.xi_crit)) ? ij.xi_crit : mean(ii.xi_crit, jj.xi_crit);
  P.tvis = (own && given(ij.tvis)) ? ij.tvis : mean(zero_if_unset(ii.tvis), zero_if_unset(jj.tvis));
  auto scale = [&](double own_value, double a, double b) {
    auto one_if_unset = [](double x) { return given(x) ? x : 1.0; };
    return (own && given(own_value)) ? own_value : mean(one_if_unset(a), one_if_unset(b));
  };
  const double ks_scale = scale(ij.ks_scale, ii.ks_scale, jj.ks_scale);
  const double kr_scale = scale(ij.kr_scale, ii.kr_scale, jj.kr_scale);
  const double kt_scale = scale(ij.kt_scale, ii.kt_scale, jj.kt_scale);

  auto channel = [&](int own_flag, int a, int b) {
    if (own && own_flag >= 0) return own_flag;
    return (a != 0 && b != 0) ? 1 : 0;    // unset (-1) counts as on
  };
  P.sliding = channel(ij.sliding, ii.sliding, jj.sliding);
  P.rolling = channel(ij.rolling, ii.rolling, jj.rolling);
  P.twisting = channel(ij.twisting, ii.twisting, jj.twisting);
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

static void write_input(FILE *fp, const PairJKRDT::Input &g)
{
  const double d[9] = {g.gamma, g.E, g.nu, g.G, g.xi_crit, g.tvis,
                       g.ks_scale, g.kr_scale, g.kt_scale};
  const int k[3] = {g.sliding, g.rolling, g.twisting};
  fwrite(d, sizeof(double), 9, fp);
  fwrite(k, sizeof(int), 3, fp);
}

void PairJKRDT::write_restart(FILE *fp)
{
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fwrite(&setflag[i][j], sizeof(int), 1, fp);
      if (setflag[i][j]) write_input(fp, in(i, j));
    }
}

void PairJKRDT::read_restart(FILE *fp)
{
  allocate();
  const int me = comm->me;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (me == 0) utils::sfread(FLERR, &setflag[i][j], sizeof(int), 1, fp, nullptr, error);
      MPI_Bcast(&setflag[i][j], 1, MPI_INT, 0, world);
      if (!setflag[i][j]) continue;
      double d[9];
      int k[3];
      if (me == 0) {
        utils::sfread(FLERR, d, sizeof(double), 9, fp, nullptr, error);
        utils::sfread(FLERR, k, sizeof(int), 3, fp, nullptr, error);
      }
      MPI_Bcast(d, 9, MPI_DOUBLE, 0, world);
      MPI_Bcast(k, 3, MPI_INT, 0, world);
      in(i, j) = {d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8], k[0], k[1], k[2]};
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
  const std::pair<const char *, double> reals[] = {
      {"gamma", g.gamma},     {"E", g.E},       {"nu", g.nu},
      {"G", g.G},             {"xi_crit", g.xi_crit}, {"tvis", g.tvis},
      {"ks_scale", g.ks_scale}, {"kr_scale", g.kr_scale}, {"kt_scale", g.kt_scale}};
  for (const auto &kv : reals)
    if (given(kv.second)) line += fmt::format(" {} {:.17g}", kv.first, kv.second);
  const std::pair<const char *, int> flags[] = {
      {"sliding", g.sliding}, {"rolling", g.rolling}, {"twisting", g.twisting}};
  for (const auto &kv : flags)
    if (kv.second >= 0) line += fmt::format(" {} {}", kv.first, kv.second ? "on" : "off");
  if (contacts_at_run_end > 0) line += fmt::format(" data_contacts {}", contacts_at_run_end);
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
