// A free object against the fixed world as rigid point contacts with the Coulomb cone, solved
// implicitly once a control period (mirror of uvms_pin/physics/world/gaps.py, the candidate
// points, and uvms_pin/physics/constraints/object_contacts.py with step.py, the rows and the
// velocity step, for one free object: its contacts are the only rows acting on it, and the
// system's mass matrix is block diagonal over the bodies).
//
// Candidates (piece, object, material point x on the piece, normal n out of the object,
// signed gap r): against a plane a polyhedron's corners, a cylinder's rim points (the lowest
// point of each rim circle; its rim's corners when it stands on an end face), else coal's
// signed distance and nearest point. A contact is solved when r <= h |J_n| |v| + margin. Its
// rows are J = C^T J_x (3 x 6), C = (t1, t2, n) the contact frame, J_x = [R, -[x - p]x R] the
// velocity of the body's material point at x for the LOCAL twist (v, w) of the pose (R, p).
// With G = J M^-1 J^T (M the 6 x 6 mass matrix, added mass included) and
// g = J v_free + phi(r) / h on the normal rows (phi(r) = r, or correction * r inside),
//
//   v+ = v_free + M^-1 J^T lambda,  sigma = G lambda + g,
//   0 <= lambda_n  _|_  sigma_n >= 0,   lambda_t = argmax dissipation in |lambda_t| <= mu lambda_n
//
// (the Coulomb problem the reference's ADMM solves in De Saxce's form), here by projected
// Gauss-Seidel: for each contact, lambda_n <- max(0, lambda_n - sigma_n / G_nn), then
// lambda_t <- proj_{|.| <= mu lambda_n}(lambda_t - sigma_t / g_t) with g_t the largest
// eigenvalue of its 2 x 2 block G_tt (a step whose fixed points are exactly the
// maximal-dissipation ones), sweeps until no impulse changes the velocity of its own rows by
// more than kTolerance (1e-10 m/s). mu is mu_k while the patch slid over the last period,
// mu_s otherwise; a patch slides when one of its points moves tangentially faster than
// 1e-6 m/s at the period's end (ObjectWorldContacts.forces).
#pragma once

#include <algorithm>
#include <vector>

#include "world_contact.hpp"

namespace uvms {

// the tangential speed above which a contact slides [m/s] (object_contacts.py's SLIP_M_S)
constexpr double kSlipSpeed_m_s = 1.0e-6;

// One candidate contact point (Candidate of gaps.py); corner: the piece's corner, a rim's
// lowest point -2 - rim, -1 coal's point, kPatchCorner - k a contact patch's vertex k.
struct ContactCandidate {
  int piece = 0, obj = 0, corner = -1;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  double gap_m = 0.0;
};

// Every candidate of the pieces placed by data (after kinematics) on the objects whose bounds
// are within reach_m [m].
void contact_candidates(const Data& data, const std::vector<ContactShape>& pieces,
                        const std::vector<ContactShape>& objects, double reach_m,
                        std::vector<ContactCandidate>& out);

// coal's signed distance and nearest point on the piece (placed at where) to the object
// (placed at object_where), the normal out of the object (_coal_candidate of gaps.py).
ContactCandidate coal_candidate(const ContactShape& piece, const pinocchio::SE3& where,
                                const ContactShape& object, const pinocchio::SE3& object_where,
                                int p, int o);

// a patch's vertex k is candidate corner kPatchCorner - k (gaps.py's PATCH_CORNER)
constexpr int kPatchCorner = -4;

// The candidates of a piece on a solid object (patch_candidates of gaps.py): the vertices of
// coal's contact patch when the two are within reach_m [m] and touch along a face or an edge
// (two vertices or more), else coal_candidate's one point; appended to out.
void patch_candidates(const ContactShape& piece, const pinocchio::SE3& where,
                      const ContactShape& object, const pinocchio::SE3& object_where, int p,
                      int o, double reach_m, std::vector<ContactCandidate>& out);

// C = (t1, t2, n) with n its third column (contact_frame of contacts.py).
Eigen::Matrix3d contact_frame(const Vec3& normal);

// J_x (3 x 6): the world velocity of the material point at x of a free body at pose `body`
// for its LOCAL twist.
Eigen::Matrix<double, 3, 6> point_jacobian(const pinocchio::SE3& body, const Vec3& x);

// The solves that stalled above kTolerance and were accepted (step.py's StalledSolves): with
// friction the problem is not a convex program, and with more contacts than freedoms (a box's
// four corners) G is singular; on a box rocking or landing on its corners the sweeps stall.
// The last impulse is kept when its residual (coulomb_residual) is at most 1e-4 of the rows'
// largest speed |g|_inf and at least 1e-5 m/s (step.py's acceptable_residual). A solve that
// stops progressing within 1e-9 m/s (a tenth of the reference ADMM's tolerance) has
// converged and is not counted.
struct StalledSolves {
  int count = 0;
  double worst_residual_m_s = 0.0;
  void add(double residual_m_s) {
    ++count;
    worst_residual_m_s = std::max(worst_residual_m_s, residual_m_s);
  }
};

// A row whose impulse lies in a box, |lambda| <= bound (a joint's Coulomb friction over the
// period h: bound = c h, step.py's box cone; bound = inf: a bilateral row, lambda of any sign).
// Its law: |lambda| < bound => sigma = 0 (it sticks); lambda = +-bound => sigma opposes lambda.
struct BoxRow {
  Eigen::Index row = 0;
  double bound = 0.0;
};

// How far impulse is from solving the problem of coulomb_gauss_seidel [m/s] (0: solved): the
// largest of each unilateral row's and contact normal's penetration -min(sigma, 0) and
// complementarity min(sigma^+, lambda G_jj), a box row's speed inside its box |sigma| or
// along its bound's side (sigma lambda > 0), a sticking contact's tangential speed, a sliding
// one's departure from maximal dissipation |sigma_t + |sigma_t| lambda_t / |lambda_t||.
double coulomb_residual(const Eigen::MatrixXd& delassus, const Eigen::VectorXd& g,
                        const std::vector<Eigen::Index>& cone_rows, const std::vector<double>& mu,
                        const std::vector<Eigen::Index>& unilateral,
                        const Eigen::VectorXd& impulse, const std::vector<BoxRow>& boxes = {});

// The Coulomb problem's projected Gauss-Seidel (see the file's comment) on the Delassus
// operator G and the free rows' velocity g: impulse (in: the start, out: the solution) with
// the cones of `cone_rows` (each a contact's first row t1, then t2, n; mu per contact) and
// the unilateral rows `unilateral` (lambda >= 0, a joint limit's) and the box rows `boxes`
// (lambda <- clamp(lambda - sigma / G_jj, -bound, bound)). From sweep 2,000 a solve
// whose residual (checked every 1,000 sweeps) no longer halves is stalled; after kMaxSweeps the last
// sweep's impulse is kept when its coulomb_residual is acceptable (StalledSolves; counted in
// stalled); otherwise throws SimulationFailure. what: for the message.
void coulomb_gauss_seidel(const Eigen::MatrixXd& delassus, const Eigen::VectorXd& g,
                          const std::vector<Eigen::Index>& cone_rows,
                          const std::vector<double>& mu,
                          const std::vector<Eigen::Index>& unilateral, Eigen::VectorXd& impulse,
                          const char* what, StalledSolves& stalled,
                          const std::vector<BoxRow>& boxes = {});

// The velocity step of one free object against its fixed world.
class ObjectContactStep {
 public:
  double margin = 1.0e-3;   // [m] the allowance of a contact's selection
  double correction = 0.2;  // beta, the fraction of a penetration removed per period

  // v (in: v_free (6,), out: v+) over the period h from the pose whose kinematics data holds
  // (q0), mass M(q0) (6 x 6), the contacts with world's objects and the sliding patches of
  // memory; rows selected with the speed max(|v|, least_speed) per coordinate, widened with
  // the solved velocity (at most 4 rounds, then once more, as step.py). Returns whether any
  // contact was solved; out: the contacts and their mean forces over the period.
  bool constrain(const WorldContactModel& world, const FrictionMemory& memory, const Data& data,
                 const Eigen::Matrix<double, 6, 6>& mass, Vec6& v, double h,
                 const Vec6& least_speed, ContactForces& out);

  // The contacts within reach at speed; returns their count. After it: their rows
  // (jacobian(), 3 a contact: t1, t2, n, for the body's LOCAL twist), the rows' drift
  // phi(r) / h (drift()) and each contact's friction (mu()).
  int select(const WorldContactModel& world, const FrictionMemory& memory, const Data& data,
             const Vec6& speed, double h);
  const Eigen::MatrixXd& jacobian() const { return jacobian_; }
  const Eigen::VectorXd& drift() const { return drift_; }
  const std::vector<double>& mu() const { return mu_; }
  // the solves of this step that stalled and were accepted
  StalledSolves stalled;
  // The selected contacts' mean forces over the period h of their impulses (3 a contact)
  // and the body's velocity v after the step.
  void forces(const Vec6& v, const Eigen::VectorXd& impulse, double h, ContactForces& out) const;

 private:
  void solve(const Eigen::Matrix<double, 6, 6>& mass, const Vec6& v_free, Vec6& v);

  std::vector<ContactCandidate> candidates_, selected_;
  std::vector<double> mu_;
  Eigen::MatrixXd jacobian_, delassus_, minv_jt_;
  Eigen::VectorXd drift_, impulse_;
  std::vector<Eigen::Matrix3d> frames_;
  std::vector<Eigen::Index> cone_rows_;
};

// A free body's pose (7,) at the period's end from its pose q and its body velocity v (6,)
// (free_body_configuration of step.py): p+ = p + h R v_lin, R+ = R exp(h w).
Eigen::Matrix<double, 7, 1> free_body_configuration(const Eigen::Ref<const Eigen::VectorXd>& q,
                                                    const Vec6& v, double h);

}  // namespace uvms
