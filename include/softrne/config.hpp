#pragma once
/// \file
/// \brief Version and assertion macros shared by every softrne header.

#include <cstdio>
#include <cstdlib>

#define SOFTRNE_VERSION_MAJOR 0
#define SOFTRNE_VERSION_MINOR 1
#define SOFTRNE_VERSION_PATCH 0

/// \brief Debug-build check of API preconditions (sizes, a Data made for another chain).
/// Prints file:line and the message, then aborts; compiled out with NDEBUG.
#ifndef NDEBUG
#define SOFTRNE_ASSERT(cond, msg)                                                       \
  do {                                                                                  \
    if (!(cond)) {                                                                      \
      std::fprintf(stderr, "%s:%d: softrne assertion failed: %s\n", __FILE__, __LINE__, \
                   msg);                                                                \
      std::abort();                                                                     \
    }                                                                                   \
  } while (false)
#else
#define SOFTRNE_ASSERT(cond, msg) \
  do {                            \
  } while (false)
#endif
