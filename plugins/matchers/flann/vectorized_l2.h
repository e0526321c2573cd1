#pragma once

// FLANN's L2 for uint8 descriptors, written so that it runs at the width of the CPU's
// vector unit: FLANN's own adds four squared differences per step into one float sum, a
// dependency chain that no compiler may reorder. Here byte against byte is summed in
// integers (exact, so any order gives the same value), and byte against a cluster
// centre (float in the search, double while the k-means tree is built) in eight
// independent float lanes, lane l taking dimensions l, l + 8, ..., added up in a fixed
// order at the end. The SSE2 and AVX2 kernels perform exactly the operations of the
// scalar reference (`ScalarL2ToCentre`, no fused multiply-add) in the same order, so
// every CPU gives the same value on every run.
//
// Together with the shorter backward search of the matcher, the lanes took the matching
// of fountain-P11 (55 pairs, 12,000 SIFT features per image) from 38.8 s to 15.2 s of
// thread time. The explicit kernels then took the matching of 20 fox images (190 pairs,
// 5,750 features per image) from 31.6 s to 16.7 s, with the same matches: distances to
// centres are most of a search and of a tree's build.

#include <cstddef>
#include <cstdint>
#include <type_traits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tessera::flann_l2 {

constexpr size_t kLanes = 8;

// The reference: eight float lanes over the dimensions, the rest into lane 0.
template <typename Centre>
float ScalarL2ToCentre(const uint8_t* a, const Centre* b, size_t size) {
  float lanes[kLanes] = {};
  size_t i = 0;
  for (; i + kLanes <= size; i += kLanes) {
    for (size_t lane = 0; lane < kLanes; ++lane) {
      const float diff = static_cast<float>(a[i + lane]) - static_cast<float>(b[i + lane]);
      lanes[lane] += diff * diff;
    }
  }
  for (; i < size; ++i) {
    const float diff = static_cast<float>(a[i]) - static_cast<float>(b[i]);
    lanes[0] += diff * diff;
  }
  return ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
         ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
}

#if defined(__x86_64__)
namespace internal {

// Adds the tail (into lane 0) and the lanes as the reference does.
inline float FinishLanes(float lanes[kLanes], const uint8_t* a, const float* b_float,
                         const double* b_double, size_t i, size_t size) {
  for (; i < size; ++i) {
    const float centre = b_float != nullptr ? b_float[i] : static_cast<float>(b_double[i]);
    const float diff = static_cast<float>(a[i]) - centre;
    lanes[0] += diff * diff;
  }
  return ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
         ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
}

// Eight centre values as two SSE vectors of floats (lanes 0-3, 4-7).
inline void LoadCentreSse(const float* b, __m128* low, __m128* high) {
  *low = _mm_loadu_ps(b);
  *high = _mm_loadu_ps(b + 4);
}
inline void LoadCentreSse(const double* b, __m128* low, __m128* high) {
  *low = _mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(b)), _mm_cvtpd_ps(_mm_loadu_pd(b + 2)));
  *high = _mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(b + 4)), _mm_cvtpd_ps(_mm_loadu_pd(b + 6)));
}

template <typename Centre>
float SseL2ToCentre(const uint8_t* a, const Centre* b, size_t size) {
  const __m128i zero = _mm_setzero_si128();
  __m128 sum_low = _mm_setzero_ps(), sum_high = _mm_setzero_ps();
  size_t i = 0;
  for (; i + kLanes <= size; i += kLanes) {
    const __m128i bytes =
        _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + i)), zero);
    const __m128 a_low = _mm_cvtepi32_ps(_mm_unpacklo_epi16(bytes, zero));
    const __m128 a_high = _mm_cvtepi32_ps(_mm_unpackhi_epi16(bytes, zero));
    __m128 b_low, b_high;
    LoadCentreSse(b + i, &b_low, &b_high);
    const __m128 diff_low = _mm_sub_ps(a_low, b_low);
    const __m128 diff_high = _mm_sub_ps(a_high, b_high);
    sum_low = _mm_add_ps(sum_low, _mm_mul_ps(diff_low, diff_low));
    sum_high = _mm_add_ps(sum_high, _mm_mul_ps(diff_high, diff_high));
  }
  alignas(16) float lanes[kLanes];
  _mm_store_ps(lanes, sum_low);
  _mm_store_ps(lanes + 4, sum_high);
  if constexpr (std::is_same_v<Centre, float>) {
    return FinishLanes(lanes, a, b, nullptr, i, size);
  } else {
    return FinishLanes(lanes, a, nullptr, b, i, size);
  }
}

// AVX2 without FMA: a multiply and an add, rounded separately as in the reference.
__attribute__((target("avx2"))) inline __m256 LoadCentreAvx(const float* b) {
  return _mm256_loadu_ps(b);
}
__attribute__((target("avx2"))) inline __m256 LoadCentreAvx(const double* b) {
  return _mm256_set_m128(_mm256_cvtpd_ps(_mm256_loadu_pd(b + 4)),
                         _mm256_cvtpd_ps(_mm256_loadu_pd(b)));
}

template <typename Centre>
__attribute__((target("avx2"))) float AvxL2ToCentre(const uint8_t* a, const Centre* b,
                                                    size_t size) {
  __m256 sum = _mm256_setzero_ps();
  size_t i = 0;
  for (; i + kLanes <= size; i += kLanes) {
    const __m256 a8 = _mm256_cvtepi32_ps(
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + i))));
    const __m256 diff = _mm256_sub_ps(a8, LoadCentreAvx(b + i));
    sum = _mm256_add_ps(sum, _mm256_mul_ps(diff, diff));
  }
  alignas(32) float lanes[kLanes];
  _mm256_store_ps(lanes, sum);
  if constexpr (std::is_same_v<Centre, float>) {
    return FinishLanes(lanes, a, b, nullptr, i, size);
  } else {
    return FinishLanes(lanes, a, nullptr, b, i, size);
  }
}

inline bool HasAvx2() {
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  return has_avx2;
}

}  // namespace internal
#endif

// The distance of bytes `a` to a centre `b`, the widest kernel the CPU runs.
template <typename Centre>
float L2ToCentre(const uint8_t* a, const Centre* b, size_t size) {
#if defined(__x86_64__)
  if (internal::HasAvx2()) return internal::AvxL2ToCentre(a, b, size);
  return internal::SseL2ToCentre(a, b, size);
#else
  return ScalarL2ToCentre(a, b, size);
#endif
}

// The distance functor FLANN's trees are built and searched with.
struct VectorizedL2Uint8 {
  typedef bool is_kdtree_distance;
  typedef unsigned char ElementType;
  typedef float ResultType;

  template <typename Iterator1, typename Iterator2>
  ResultType operator()(Iterator1 a, Iterator2 b, size_t size,
                        ResultType /*worst_dist*/ = -1) const {
    using A = std::remove_cv_t<std::remove_reference_t<decltype(*a)>>;
    using B = std::remove_cv_t<std::remove_reference_t<decltype(*b)>>;
    if constexpr (std::is_integral_v<A> && std::is_integral_v<B>) {
      int32_t sum = 0;  // at most 255^2 per dimension: exact up to 33,000 dimensions
      for (size_t i = 0; i < size; ++i) {
        const int32_t diff = static_cast<int32_t>(a[i]) - static_cast<int32_t>(b[i]);
        sum += diff * diff;
      }
      return static_cast<ResultType>(sum);
    } else if constexpr (std::is_integral_v<A>) {
      return L2ToCentre<B>(&a[0], &b[0], size);
    } else {
      return L2ToCentre<A>(&b[0], &a[0], size);  // the same sum: (a - b)^2 = (b - a)^2
    }
  }

  // Used by kd-trees only (one dimension of a partial distance).
  template <typename U, typename V>
  ResultType accum_dist(const U& a, const V& b, int) const {
    return static_cast<ResultType>((a - b) * (a - b));
  }
};

}  // namespace tessera::flann_l2
