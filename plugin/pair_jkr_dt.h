/* jkr/dt: pair style for the contact model of Dominik & Tielens made
   energy-conserving by Wada et al. (2007).

   This class is the LAMMPS glue, in layers that call downward only:
     pair_jkr_dt.cpp             its own state, the look-ups, the local view
     pair_jkr_dt_init.cpp        init_style: checks, constants, the contact store
     pair_jkr_dt_loop.cpp        the neighbor-list loop: threads, blocks of pairs,
                                 the LEAN runs, the sums
     pair_jkr_dt_step.h          one pair's step: motion, guards, the contact kernel,
                                 loads, dissipation and energy bookkeeping
     pair_jkr_dt_coeff.cpp       the pair_coeff keywords, mixing, data and restart files
     pair_jkr_dt_guards.cpp      t_c, the time-step limits, the errors of a run
     pair_jkr_dt_bins.cpp        bins that grow with the box
     pair_jkr_dt_tangential.cpp  a tangential channel switched off between runs
   The contact physics lives in jkr_dt_contact.h (normal: jkr_dt_normal.h,
   tangential: jkr_dt_tangential.h); the contact state in FixJKRDTContacts.  */

#ifndef JKR_DT_PAIR_H
#define JKR_DT_PAIR_H

#include "pair.h"

// the AVX2 pair loop: GCC and Clang on x86-64 (three-operand SSE/AVX instructions, no fused
// multiply-add, so the same bits as the portable loop)
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define JKRDT_AVX2 1
#else
#define JKRDT_AVX2 0
#endif

#include "fix_jkr_dt_contacts.h"
#include "jkr_dt_contact.h"

#include <string>
#include <vector>

namespace LAMMPS_NS {

class PairJKRDT : public Pair {
 public:
  // the pair_coeff keywords; their table (pair_jkr_dt_coeff.cpp) says how each is read,
  // checked, mixed and written to data and restart files
  enum Key { GAMMA, E, NU, G, XI_CRIT, TVIS, KS_SCALE, KR_SCALE, KT_SCALE,
             SLIDING, ROLLING, TWISTING, DAMP_TENSION, NKEY };
  // what pair_coeff gave for one type pair, by keyword: NaN = not given; a switch is 1 or 0
  struct Input {
    double v[NKEY];
    bool given(Key k) const { return v[k] == v[k]; }
  };

  // the parameters of one type pair after defaults and mixing: the kernel's
  // coefficients (jkr_dt_contact.h) and what they were made from
  struct Param : JKRDT::Coefficients {
    double Estar;       // reduced Young's modulus, eq. (2)
    double Gstar;       // G* of the sliding stiffness, eq. (13)
    double Gred;        // reduced shear modulus (1/G1 + 1/G2)^-1 of eqs. (26), (35), (37)
    double nu;          // Poisson ratio in the damping of eq. (A.5)
    double tvis;        // viscoelastic time scale of eq. (A.5)
    double cut;         // reach of a stretched contact between the largest radii
  };

  // one bonded contact, as the local compute reports it
  struct ContactView {
    tagint id1, id2;    // atom IDs, id1 < id2
    double delta;       // compression length, eq. (3)
    double a;           // contact radius, eq. (4)
    double force;       // normal force on atom id1 along x1 - x2 (elastic + damping)
    double zeta, xi, phi;    // |zeta|, |xi|, |phi|, eqs. (10), (20), (24); 0 if off
  };

  static constexpr int NPVECTOR = JKRDT::NVALUE;    // compute pair jkr/dt's values
  static const char *const FIX_ID;
  // the group of grains in fragments that have left the collision for good (fix
  // jkr/dt/settle depart): they keep their velocities but no longer move or interact
  static const char *const DEPARTED_GROUP;

  // time-step guards (pair_jkr_dt_guards.cpp), in units of t_c = sqrt(m delta_c / F_c), eq. (49)
  static constexpr double DT_WARN = 0.1;      // above: energy errors of 1e-3 and more
  static constexpr double DT_STABLE = 0.4;    // above: the integration cannot hold
  static constexpr double STEP_WARN = 0.5;    // warn: a contact moved this * delta_c in one step
  static constexpr double LATE_SLACK = 1e-3;  // a new contact may be this * delta_c deeper than
                                              // a step's normal travel (curvature of the path)
  enum DtCheck { DT_CHECK_OFF = 0, DT_CHECK_WARN, DT_CHECK_ERROR };

  PairJKRDT(class LAMMPS *);
  ~PairJKRDT() override;

  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double init_one(int, int) override;
  void write_restart(FILE *) override;
  void read_restart(FILE *) override;
  void write_restart_settings(FILE *) override;
  void read_restart_settings(FILE *) override;
  void write_data(FILE *) override;
  void write_data_all(FILE *) override;
  double memory_usage() override;

  bool bonded_contact(int i, int j, ContactView &view) const;
  // the pair style found by its style name (in a hybrid too), or null
  static PairJKRDT *active(class LAMMPS *lmp);

  // what the contact store asks of its writer (FixJKRDTContacts::Writer)
  void run_ended();                   // the largest step a contact took this run
  [[noreturn]] void contact_lost();   // a stored contact missing from the list
  double t_c() const { return tc_min; }
  // the least energy that breaks a bonded contact, eq. (6) from equilibrium to -delta_c,
  // over the type pairs present, and the mass of the lightest grain
  double weakest_contact(double &lightest) const;
  // the contact store with its per-atom rows current (for readers between the steps)
  FixJKRDTContacts *contacts();
  // bins that grow with the box (pair_jkr_dt_bins.cpp); before each reneighboring
  static constexpr double BINS_PER_GRAIN = 32.0;
  // the neighbor bins are outgrown when the side they need is this much wider than the
  // side of this run's bins (a factor 1.95 in their number)
  static constexpr double BINS_OUTGROWN = 1.25;
  // cutneigh: the neighbor cutoff (Neighbor's cutneighmax once it is set up)
  void fit_bins(double cutneigh);
  // fit_bins when a run is set up, taking the side its neighbor bins will have
  void start_bins(double cutneigh);
  // LAMMPS takes the neighbor bin size at a run's start only: true once the box has
  // outgrown this run's bins, so that a new run (which fix jkr/dt/settle asks for at its
  // next check) would bin the grains in BINS_PER_GRAIN per grain again
  bool bins_outgrown() const { return bins_stale; }

 protected:
  std::vector<Input> input;    // (ntypes+1)^2, row-major
  std::vector<Param> param;
  std::vector<double> maxrad;  // largest radius of each type
  std::vector<double> minrad;  // smallest radius of each type (t_c)
  std::vector<double> minmass; // smallest mass of each type (t_c)
  // contact constants of each type pair when every type has one radius (the usual
  // monodisperse scene): looked up, never recomputed, in the pair loop
  std::vector<JKRDT::ContactConstants> type_constants;
  bool one_radius_per_type;
  bool any_tangential;         // some type pair present has a tangential channel
  int scene_pair;              // a type pair whose constants every pair present shares; -1: none
  enum ConstantsBy { BY_SCENE, BY_TYPE, BY_RADII };
  ConstantsBy constants_by();
  ConstantsBy constants_source;   // the last answer of constants_by() ...
  bigint radii_checked;           // ... checked at this neighbor list build
  bool radii_adapt;               // a fix adapt may change radii at any step
  int dt_check;                // DtCheck: what a time step above DT_STABLE t_c does
  double tc_min;               // smallest t_c over the type pairs present
  int tc_types[2];             // the type pair of tc_min
  double tc_logged, dt_logged; // last values written to the log
  double dt_warned;            // the time step last checked (warnings once per dt)
  bigint checked_laststep;     // the run whose time step was checked
  double step_max;             // largest |v_n| dt / delta_c of a contact this run, this rank
  bool step_warned;            // the warning of run_ended() is given once
  bigint contacts_at_run_end;  // bonded contacts when the last run ended (write_data marks it)
  bigint data_contacts;        // contacts a data file read by read_data left behind
  FixJKRDTContacts *fix_contacts;
  int departed_bit;            // mask bit of DEPARTED_GROUP; 0 while the group does not exist
  bool bins_bounded;           // pair_style ... bins bounded (default) or box
  double bin_size_set;         // the neighbor and sort bin size fit_bins() set last (0: LAMMPS's)
  double bin_size_logged;      // the bin size last written to the log
  double bin_size_run;         // the side of this run's neighbor bins (set at its start)
  bool bins_stale;             // the box has outgrown this run's neighbor bins

  int nstride;                 // ntypes + 1
  Input &in(int i, int j) { return input[i * nstride + j]; }
  const Input &in(int i, int j) const { return input[i * nstride + j]; }
  const Param &par(int i, int j) const { return param[i * nstride + j]; }

  void allocate();
  Param resolve(int i, int j) const;
  int layout_mask() const;
  void book_channels_switched_off(const std::vector<Param> &fresh, FixJKRDTContacts &C);
  // the constants of every type pair as the contact fix keeps them (made_with) and restart
  // files carry them: each field by name (pair_jkr_dt_made_with.cpp); a record lacking a
  // field this build needs reads back empty
  static std::vector<double> made_with_record(const std::vector<Param> &param);
  static std::vector<Param> made_with_params(const std::vector<double> &record);
  // init_style's parts (pair_jkr_dt_init.cpp)
  void check_atom_style() const;
  void find_contact_constants();
  void choose_kernel();
  void attach_contact_store();
  void find_max_radii();
  void check_periodic_images(double cutmax);
  void check_neighbor_settings() const;
  void check_integrator() const;
  void check_data_file_contacts() const;
  std::string coeff_words(const Input &g) const;
  void warn_data_file() const;
  void find_contact_time();
  void check_time_step();
  [[noreturn]] void report_overlap(int p, int q, double delta, const JKRDT::NormalScales &S) const;
  [[noreturn]] void report_blow_up(int p, int q, double r) const;
  [[noreturn]] void report_fast_pair(int p, int q, double vn) const;
  [[noreturn]] void report_late_contact(int p, int q, double delta, double step,
                                        const JKRDT::NormalScales &S) const;
  [[noreturn]] void report_not_finite(int p, int q, const char *what) const;
  // what one thread's share of the pair loop adds up. Each thread owns the atoms of its
  // range of the list: it adds to their forces, torques and ledger directly, and keeps
  // what it adds to other threads' atoms in 'far', added after the loop in thread order
  struct Trouble {
    enum Kind { NONE = 0, BLOW_UP, FAST_PAIR, OVERLAP, LATE, NOT_FINITE } kind = NONE;
    int p = 0, q = 0;
    double a = 0.0, b = 0.0;
    JKRDT::NormalScales S{};
  };
  struct FarLoad {
    int atom;
    double f[3], torque[3], loss[JKRDT::NLEDGER];    // loss: the ledger's columns
  };
  struct Accumulator {
    int thread;
    const int *thread_of;           // owning thread of each owned atom; null: one thread
    std::vector<FarLoad> far;
    double upot, utan[JKRDT::NCHANNEL], eng, virial[6], step_max;
    bigint contact_ends;            // bonded contacts counted once per owned atom
    Trouble trouble;                // the first problem met; the thread stops there
  };
  // the pair loop's parts (pair_jkr_dt_step.h): what a pair's step reads, the constants'
  // look-up, how a pair's evaluation ends, a pair as evaluated, a block of the list's
  // pairs, one pair's step (general or LEAN), and one thread's pass (pair_jkr_dt_loop.cpp)
  struct View;
  struct Constants;
  enum class Eval;
  struct Done;
  template <bool TANGENTIAL> struct Block;
  template <bool TANGENTIAL, bool LEAN> struct PairStep;
  template <bool TANGENTIAL, bool AVX2> struct Pass;
  View view(int eflag, bool tally_atoms, ConstantsBy by, const Accumulator &acc) const;
  bool lean_enabled = true;    // pair_style ... lean yes (default) or no: every pair takes
                               // the general step (the same bits, slower; for testing)
  // the pair loop, written once and compiled twice: for any x86-64 (SSE2) and for CPUs
  // with AVX2 (AVX2: the instantiation its out-of-line parts are compiled for too), chosen
  // when the run starts (pair_style ... kernel auto|portable)
  template <bool TANGENTIAL, bool AVX2>
  [[gnu::always_inline]] inline void pair_loop(int ii_from, int ii_to, int eflag,
                                               bool tally_atoms, ConstantsBy by,
                                               Accumulator &acc);
  template <bool TANGENTIAL>
  void pair_loop_portable(int ii_from, int ii_to, int eflag, bool tally_atoms, ConstantsBy by,
                          Accumulator &acc);
#if JKRDT_AVX2
  template <bool TANGENTIAL>
  __attribute__((target("avx2"), flatten)) void pair_loop_avx2(int ii_from, int ii_to,
                                                               int eflag, bool tally_atoms,
                                                               ConstantsBy by, Accumulator &acc);
#endif
  bool kernel_auto;    // pair_style ... kernel auto (default) or portable
  bool kernel_avx2;    // this run's loop is the AVX2 one
  bool kernel_logged = false;
  bool lean_logged = true;
  [[noreturn]] void report(const Trouble &t) const;
  int nthreads_used() const;
  std::vector<int> thread_from;       // first ilist entry of each thread (threaded runs) ...
  std::vector<int> thread_of;         // ... the owning thread of each owned atom ...
  bigint thread_of_build = -1;        // ... for the list of this build
  int thread_of_threads = 0;          // ... and this many threads
  std::vector<Accumulator> accumulators;
  // the list's pairs in slot order, oriented as evaluated (follow_slots), so that the
  // distance test runs over one flat array: no loop per atom, whose exit (after ~1
  // neighbor, a varying number) the CPU mispredicts, and no IDs looked up per pair
  struct SlotPair {
    int p, q;    // particles 1 and 2
  };
  std::vector<SlotPair> slot_pair;
  bigint slot_pair_made = -1;         // the contact fix's slots_made() they follow ...
  bool slot_pair_oriented = false;    // ... and whether by ID (any_tangential)
  void follow_slots();
  int threads_logged;          // threads per rank last written to the log
  void fill_pvector(double upot, const double *utan, double contacts);
};

}    // namespace LAMMPS_NS

#endif
