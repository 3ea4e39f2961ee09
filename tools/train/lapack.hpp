#pragma once
// The few BLAS/LAPACK routines the exact GP trainer hands its O(N^3) steps
// to, through the Fortran interface of the optimised library it links
// (Debian's OpenBLAS: AVX2/FMA kernels picked at run time, threaded). On
// column-major Eigen matrices; host tools only, never the model library.
//
// Each wrapper returns LAPACK's info (0 on success).

#include <cstddef>

#include <Eigen/Core>

extern "C" {
// Fortran character arguments carry a hidden length after the named ones.
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t uplo_len);
void dpotri_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t uplo_len);
void dpotrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda, double* b,
             const int* ldb, int* info, std::size_t uplo_len);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc, std::size_t transa_len, std::size_t transb_len);
// OpenBLAS's own: the threads its calls use, for the whole process.
int openblas_get_num_threads();
void openblas_set_num_threads(int threads);
}

namespace cdcr::training::lapack {

namespace detail {
// dpotrf_ and dpotri_: the lower triangle of a square matrix, in place.
using InPlaceLowerRoutine = void(const char*, const int*, double*, const int*, int*, std::size_t);
inline int in_place_lower(InPlaceLowerRoutine routine, Eigen::Ref<Eigen::MatrixXd> a) {
  const int n = static_cast<int>(a.rows());
  const int lda = static_cast<int>(a.outerStride());
  int info = 0;
  routine("L", &n, a.data(), &lda, &info, 1);
  return info;
}
}  // namespace detail

// Lower Cholesky factor of the lower triangle of a, in place (the strict
// upper triangle is left alone). info > 0: the leading minor of that order
// is not positive definite.
inline int cholesky_lower(Eigen::Ref<Eigen::MatrixXd> a) { return detail::in_place_lower(dpotrf_, a); }

// b <- (L L^T)^-1 b for the lower factor l.
inline int cholesky_solve_lower(const Eigen::Ref<const Eigen::MatrixXd>& l, Eigen::Ref<Eigen::MatrixXd> b) {
  const int n = static_cast<int>(l.rows());
  const int lda = static_cast<int>(l.outerStride());
  const int nrhs = static_cast<int>(b.cols());
  const int ldb = static_cast<int>(b.outerStride());
  int info = 0;
  dpotrs_("L", &n, &nrhs, l.data(), &lda, b.data(), &ldb, &info, 1);
  return info;
}

// The lower factor l of K, in place, to the lower triangle of K^-1.
inline int inverse_from_cholesky_lower(Eigen::Ref<Eigen::MatrixXd> l) { return detail::in_place_lower(dpotri_, l); }

// c <- a b (general dense product).
inline void multiply(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b,
                     Eigen::Ref<Eigen::MatrixXd> c) {
  const int m = static_cast<int>(a.rows());
  const int n = static_cast<int>(b.cols());
  const int k = static_cast<int>(a.cols());
  const int lda = static_cast<int>(a.outerStride());
  const int ldb = static_cast<int>(b.outerStride());
  const int ldc = static_cast<int>(c.outerStride());
  const double one = 1.0;
  const double zero = 0.0;
  dgemm_("N", "N", &m, &n, &k, &one, a.data(), &lda, b.data(), &ldb, &zero, c.data(), &ldc, 1, 1);
}

}  // namespace cdcr::training::lapack

namespace cdcr::training::blas_threads {

// The BLAS on one thread per call while it lives (callers run their own
// threads side by side), the previous setting restored after.
class SingleThreaded {
 public:
  SingleThreaded() : previous_(openblas_get_num_threads()) { openblas_set_num_threads(1); }
  ~SingleThreaded() { openblas_set_num_threads(previous_); }
  SingleThreaded(const SingleThreaded&) = delete;
  SingleThreaded& operator=(const SingleThreaded&) = delete;

 private:
  int previous_;
};

}  // namespace cdcr::training::blas_threads
