// Consumer of the installed (or add_subdirectory'd) softrne core.
#if __has_include(<softrne/softrne.hpp>)
#include <softrne/softrne.hpp>
#endif
#include <cstdio>

#include <Eigen/Core>

#include <softrne/config.hpp>

int main() {
  static_assert(
      SOFTRNE_VERSION_MAJOR >= 0 && SOFTRNE_VERSION_MINOR >= 0 && SOFTRNE_VERSION_PATCH >= 0,
      "version macros");
  Eigen::Vector3d g(0.0, 0.0, 9.81);
  SOFTRNE_ASSERT(g.norm() > 0.0, "gravity");
  std::printf("softrne %d.%d.%d consumer ok\n", SOFTRNE_VERSION_MAJOR, SOFTRNE_VERSION_MINOR,
              SOFTRNE_VERSION_PATCH);
  return 0;
}
