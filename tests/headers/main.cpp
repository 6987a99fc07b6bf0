// The real check is that the generated translation units (one per public header)
// compiled and linked together; see CMakeLists.txt.
#include <cstdio>

int main() {
  std::printf("%d public softrne headers compiled on their own\n", SOFTRNE_HEADER_COUNT);
  return 0;
}
