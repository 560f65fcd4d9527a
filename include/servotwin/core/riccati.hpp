#pragma once
/// \file
/// Continuous-time algebraic Riccati and Lyapunov equations: the LQR/Kalman–Bucy gains of the
/// harmonic observer (frf) and, later, of LQG controller design (tuning).
///
/// Errors: like the other numerical kernels of `core`, inconsistent shapes, non-finite entries and
/// an R that is not symmetric positive definite are programming errors and throw
/// std::invalid_argument. A problem without a stabilizing solution (the Hamiltonian has
/// eigenvalues on the imaginary axis, i.e. (A, B) not stabilizable or (Q, A) not detectable)
/// throws std::domain_error. Callers that take the matrices from users check them first and report
/// core::InputError.

#include <Eigen/Dense>

namespace servotwin::core {

/// Diagnostics of a Riccati solve.
struct CareReport {
  int sign_iterations = 0;       ///< Newton iterations of the Hamiltonian matrix sign function
  int refinement_steps = 0;      ///< Newton–Kleinman steps applied after the sign function
  double relative_residual = 0;  ///< ||Res(X)||_F / (||Q||_F + ||A^T X + X A||_F + ||X G X||_F)
};

/// Stabilizing solution X = X^T of the control-form CARE
///   A^T X + X A - X B R^-1 B^T X + Q = 0,
/// so that A - B K with K = R^-1 B^T X is Hurwitz. Q must be symmetric (n x n), R symmetric
/// positive definite (m x m), B n x m.
///
/// Method: matrix sign function of the Hamiltonian [[A, -G], [-Q, -A^T]] (G = B R^-1 B^T) with
/// determinant scaling (Byers 1987), the stable invariant subspace read off by a QR least-squares
/// solve (Roberts), then Newton–Kleinman refinement steps on the residual (each a Lyapunov solve
/// by Bartels–Stewart on a complex Schur form) until the residual stops decreasing. `report`, when
/// given, receives iteration counts and the final relative residual.
Eigen::MatrixXd solve_care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R, CareReport* report = nullptr);

/// The stabilizing solution X = X^T of A^T X + X A - X G X + Q = 0 (A - G X Hurwitz) for symmetric
/// G and Q of any inertia: the Riccati equations of H-infinity synthesis, where G = B R^-1 B^T
/// with an indefinite R (core/hinf.hpp). Same method and diagnostics as solve_care. Throws
/// std::invalid_argument for shapes, non-finite or non-symmetric G, Q; std::domain_error when the
/// Hamiltonian [[A, -G], [-Q, -A^T]] has eigenvalues on the imaginary axis or its stable
/// invariant subspace is not a graph [I; X] (no stabilizing solution), and when the relative
/// residual exceeds `residual_tolerance` (in [1e-14, 1e-2]; solve_care uses 1e-8). H-infinity
/// synthesis passes a looser one: near the optimum its equations are ill-conditioned, and it
/// checks the closed loop the solution leads to instead.
Eigen::MatrixXd solve_care_indefinite(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G, const Eigen::MatrixXd& Q,
                                      CareReport* report = nullptr, double residual_tolerance = 1e-8);

/// Filter (Kalman–Bucy) form: the stabilizing Y = Y^T of
///   A Y + Y A^T - Y C^T V^-1 C Y + W = 0,
/// so that A - L C with L = Y C^T V^-1 is Hurwitz. W (n x n) is the process-noise intensity
/// (G W G^T for a noise input matrix G), V (p x p) the measurement-noise intensity. This is
/// solve_care(A^T, C^T, W, V).
Eigen::MatrixXd solve_care_filter(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& W,
                                  const Eigen::MatrixXd& V, CareReport* report = nullptr);

/// Solution X of the Lyapunov equation A^T X + X A + Q = 0 (Bartels–Stewart on the complex
/// Schur form of A). Unique when no two eigenvalues of A satisfy conj(l_i) + l_j = 0; otherwise
/// throws std::domain_error. Q need not be symmetric; for symmetric Q the result is symmetrized.
Eigen::MatrixXd solve_lyapunov(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q);

}  // namespace servotwin::core
