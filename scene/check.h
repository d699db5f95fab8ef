#pragma once
// Always-on invariant check: a broken invariant inside the code (never bad user
// input, which throws with a message) aborts with file and line.

#include <cstdio>
#include <cstdlib>

#define SANDBOX_CHECK(condition)                                                         \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                      \
    }                                                                                    \
  } while (false)
