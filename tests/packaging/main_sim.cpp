// Consumer of softrne::sim (and softrne::fit): the exported targets must bring the
// include paths and libraries of SUNDIALS CVODE and NLopt.
#include <cstdio>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <softrne/config.hpp>

#if defined(CONSUMER_HAS_FIT)
#include <nlopt.h>
#endif

int main() {
  SUNContext ctx = nullptr;
  if (SUNContext_Create(nullptr, &ctx) != 0) return 1;
  N_Vector y = N_VNew_Serial(2, ctx);
  void* mem = CVodeCreate(CV_BDF, ctx);
  const bool ok = (y != nullptr) && (mem != nullptr);
  CVodeFree(&mem);
  N_VDestroy(y);
  SUNContext_Free(&ctx);
#if defined(CONSUMER_HAS_FIT)
  int major = 0, minor = 0, bugfix = 0;
  nlopt_version(&major, &minor, &bugfix);
  std::printf("NLopt %d.%d.%d\n", major, minor, bugfix);
#endif
  std::printf("softrne::sim consumer %s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
