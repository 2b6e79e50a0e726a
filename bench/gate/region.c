/* The measured region of the benchmark gate's Python calls (bench/gate/gate.py
 * compiles this with the system C compiler and loads it with ctypes).
 *
 * Under `valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no`,
 * ivt_bench_start() switches instrumentation on once the interpreter, numpy and
 * ivt are imported (the imports run uninstrumented, which is faster), and
 * ivt_bench_measure(cb, name) counts the instructions of one call of `cb` alone
 * and dumps them under `name`. Outside valgrind the requests are no-ops. */
#include <valgrind/callgrind.h>

void ivt_bench_start(void) { CALLGRIND_START_INSTRUMENTATION; }

int ivt_bench_measure(int (*cb)(void), const char *name) {
  CALLGRIND_ZERO_STATS;
  CALLGRIND_TOGGLE_COLLECT;
  int r = cb();
  CALLGRIND_TOGGLE_COLLECT;
  CALLGRIND_DUMP_STATS_AT(name);
  return r;
}
