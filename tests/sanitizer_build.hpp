#pragma once
// Whether this test binary is built with AddressSanitizer (.ci/run's phase 2), where code runs
// 20-40 times slower than in Release. A test that repeats one check over many random data sets
// for a statistic may use fewer of them there: under the sanitizers the point is every line the
// code runs, which the first data sets already run; the statistic is checked in Release.

namespace softrne_test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

}  // namespace softrne_test
