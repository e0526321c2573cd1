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
// Distances to centres are most of a search and of a tree's build, so these kernels set
// the matcher's speed; the matching benchmarks (docs/benchmarks.md, `flann` rows)
// measure it, with the same matches as the scalar reference.

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

// AvxL2ToCentre's end for a query given as floats: the tail into lane 0, then the lanes.
__attribute__((target("avx2"))) inline float FinishCentreLanes(__m256 sum, const float* a_float,
                                                               const float* centre, size_t i,
                                                               size_t size) {
  alignas(32) float lanes[kLanes];
  _mm256_store_ps(lanes, sum);
  for (; i < size; ++i) {
    const float diff = a_float[i] - centre[i];
    lanes[0] += diff * diff;
  }
  return ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
         ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
}

// The distances of one query to `count` float centres stored one after another, four
// centres at a time so that their sums do not wait on each other. `a_float` holds the
// query's bytes as floats (exact), which saves converting them again for every centre.
// Each centre's eight lanes and tail take the reference's operations in its order, so
// every value is L2ToCentre's.
__attribute__((target("avx2"))) inline void AvxL2ToCentres(const float* a_float,
                                                           const float* centres, size_t count,
                                                           size_t size, float* out) {
  const size_t vector_end = size - size % kLanes;
  size_t c = 0;
  for (; c + 4 <= count; c += 4) {
    const float* c0 = centres + c * size;
    const float* c1 = c0 + size;
    const float* c2 = c1 + size;
    const float* c3 = c2 + size;
    __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps(), s2 = _mm256_setzero_ps(),
           s3 = _mm256_setzero_ps();
    for (size_t i = 0; i < vector_end; i += kLanes) {
      const __m256 a8 = _mm256_loadu_ps(a_float + i);
      const __m256 d0 = _mm256_sub_ps(a8, _mm256_loadu_ps(c0 + i));
      const __m256 d1 = _mm256_sub_ps(a8, _mm256_loadu_ps(c1 + i));
      const __m256 d2 = _mm256_sub_ps(a8, _mm256_loadu_ps(c2 + i));
      const __m256 d3 = _mm256_sub_ps(a8, _mm256_loadu_ps(c3 + i));
      s0 = _mm256_add_ps(s0, _mm256_mul_ps(d0, d0));
      s1 = _mm256_add_ps(s1, _mm256_mul_ps(d1, d1));
      s2 = _mm256_add_ps(s2, _mm256_mul_ps(d2, d2));
      s3 = _mm256_add_ps(s3, _mm256_mul_ps(d3, d3));
    }
    out[c] = FinishCentreLanes(s0, a_float, c0, vector_end, size);
    out[c + 1] = FinishCentreLanes(s1, a_float, c1, vector_end, size);
    out[c + 2] = FinishCentreLanes(s2, a_float, c2, vector_end, size);
    out[c + 3] = FinishCentreLanes(s3, a_float, c3, vector_end, size);
  }
  for (; c < count; ++c) {
    const float* centre = centres + c * size;
    __m256 sum = _mm256_setzero_ps();
    for (size_t i = 0; i < vector_end; i += kLanes) {
      const __m256 diff = _mm256_sub_ps(_mm256_loadu_ps(a_float + i), _mm256_loadu_ps(centre + i));
      sum = _mm256_add_ps(sum, _mm256_mul_ps(diff, diff));
    }
    out[c] = FinishCentreLanes(sum, a_float, centre, vector_end, size);
  }
}

// Bytes against bytes, sixteen dimensions a step: squared differences summed in pairs
// and in eight integer lanes, exact.
__attribute__((target("avx2"))) inline int32_t AvxL2Bytes(const uint8_t* a, const uint8_t* b,
                                                          size_t size) {
  __m256i sum = _mm256_setzero_si256();
  size_t i = 0;
  for (; i + 16 <= size; i += 16) {
    const __m256i a16 =
        _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i)));
    const __m256i b16 =
        _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i)));
    const __m256i diff = _mm256_sub_epi16(a16, b16);
    sum = _mm256_add_epi32(sum, _mm256_madd_epi16(diff, diff));
  }
  alignas(32) int32_t lanes[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), sum);
  int32_t total = 0;
  for (const int32_t lane : lanes) total += lane;
  for (; i < size; ++i) {
    const int32_t diff = static_cast<int32_t>(a[i]) - static_cast<int32_t>(b[i]);
    total += diff * diff;
  }
  return total;
}

// Bytes `a` against `count` byte rows stored one after another, AvxL2Bytes on each.
__attribute__((target("avx2"))) inline void AvxL2BytesToRows(const uint8_t* a, const uint8_t* rows,
                                                             size_t count, size_t size,
                                                             int32_t* out) {
  for (size_t r = 0; r < count; ++r) out[r] = AvxL2Bytes(a, rows + r * size, size);
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

// The distances of bytes `a` to `count` float centres stored one after another, each
// L2ToCentre's value. `a_float`: the same query as floats, `size` of them.
inline void L2ToCentres(const uint8_t* a, const float* a_float, const float* centres, size_t count,
                        size_t size, float* out) {
#if defined(__x86_64__)
  if (internal::HasAvx2()) {
    internal::AvxL2ToCentres(a_float, centres, count, size, out);
    return;
  }
#endif
  (void)a_float;
  for (size_t c = 0; c < count; ++c) out[c] = L2ToCentre(a, centres + c * size, size);
}

// Bytes against bytes: exact in integers (at most 255^2 per dimension, so up to 33,000
// dimensions), hence the same value from every kernel.
inline int32_t ScalarL2Bytes(const uint8_t* a, const uint8_t* b, size_t size) {
  int32_t sum = 0;
  for (size_t i = 0; i < size; ++i) {
    const int32_t diff = static_cast<int32_t>(a[i]) - static_cast<int32_t>(b[i]);
    sum += diff * diff;
  }
  return sum;
}

inline int32_t L2Bytes(const uint8_t* a, const uint8_t* b, size_t size) {
#if defined(__x86_64__)
  if (internal::HasAvx2()) return internal::AvxL2Bytes(a, b, size);
#endif
  return ScalarL2Bytes(a, b, size);
}

// Bytes `a` against `count` byte rows stored one after another, each L2Bytes's value.
inline void L2BytesToRows(const uint8_t* a, const uint8_t* rows, size_t count, size_t size,
                          int32_t* out) {
#if defined(__x86_64__)
  if (internal::HasAvx2()) {
    internal::AvxL2BytesToRows(a, rows, count, size, out);
    return;
  }
#endif
  for (size_t r = 0; r < count; ++r) out[r] = ScalarL2Bytes(a, rows + r * size, size);
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
      return static_cast<ResultType>(L2Bytes(&a[0], &b[0], size));
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
