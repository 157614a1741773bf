// LU with partial pivoting of a sparse matrix stored as a band, after a
// reverse Cuthill-McKee ordering: LAPACK's dgbtf2 / dgbtrs written out, so
// that its rounding is the same in every process (OpenBLAS's dgbtrf gives
// other last digits with 2 threads than with 1, and the server and the
// tests load different BLAS builds). On the step matrices of small arrays
// it factors and solves in a third to a half of UMFPACK's time, which there
// goes into assembling and searching many small fronts, not arithmetic.
// Its cost grows as n b^2, so larger arrays keep UMFPACK (worthwhile()).
#pragma once

#include <Eigen/SparseCore>
#include <vector>

namespace hj {

class BandLU {
 public:
  // Orders the pattern of a (square; the pattern of a + a^T is used) and
  // lays out the band. Call again when the pattern changes.
  void analyze(const Eigen::SparseMatrix<double>& a);

  // True when a band factorisation of the analysed pattern is expected to
  // beat a multifrontal one (a flop estimate against a measured crossover).
  bool worthwhile() const;

  // Factorises a (the analysed pattern). False if a is exactly singular.
  bool factorize(const Eigen::SparseMatrix<double>& a);

  // dx = a^-1 r with the last factorisation.
  void solve(const Eigen::VectorXd& r, Eigen::VectorXd& dx) const;

  int half_bandwidth() const { return bandwidth_; }
  // The position of row / column i of the analysed matrix in the band.
  int ordered_index(int i) const { return new_of_[i]; }

 private:
  int n_ = 0;
  int bandwidth_ = 0;          // kl = ku
  int ldab_ = 0;               // 2 kl + ku + 1, LAPACK's band storage
  std::vector<int> position_;  // band storage index of each stored nonzero, in a's order
  std::vector<int> new_of_;    // ordered index of each row / column
  std::vector<double> band_;
  std::vector<int> pivots_;
  mutable Eigen::VectorXd work_;
};

}  // namespace hj
