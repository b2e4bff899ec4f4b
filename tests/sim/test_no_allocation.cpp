// The step loop allocates nothing (STYLE.md: no allocation in per-step loops): every heap
// allocation between the first and the last on_step call is counted, whoever makes it. This
// test binary interposes the C allocator (malloc, calloc, realloc, reallocarray and the
// aligned ones: posix_memalign, aligned_alloc, memalign, valloc, pvalloc; MuJoCo's mju_malloc
// is posix_memalign) and replaces every global operator new (plain, array, nothrow, aligned),
// forwarding to glibc's own __libc_* functions. A symbol defined in the executable wins over
// libc's for every shared library too (ELF interposition), so MuJoCo's and libstdc++'s
// allocations are counted as well as ours.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#include "kinematics/xy_stage.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace {
std::atomic<long> g_allocations{0};

void count_allocation() {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
}

// a pointer the optimiser must assume is used (so that no allocation is elided)
void escape(void* p) {
  asm volatile("" : : "g"(p) : "memory");
}
}  // namespace

// glibc's allocator under its internal names (exported by libc.so.6)
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void* __libc_valloc(std::size_t size);
void* __libc_pvalloc(std::size_t size);
void __libc_free(void* p);
}

// the C allocator, counted
extern "C" {
void* malloc(std::size_t size) noexcept {
  count_allocation();
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  count_allocation();
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  count_allocation();
  return __libc_realloc(p, size);
}
void* reallocarray(void* p, std::size_t count, std::size_t size) noexcept {
  count_allocation();
  if (size != 0 && count > static_cast<std::size_t>(-1) / size) {
    errno = ENOMEM;
    return nullptr;
  }
  return __libc_realloc(p, count * size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  count_allocation();
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  count_allocation();
  return __libc_memalign(alignment, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  count_allocation();
  return __libc_memalign(alignment, size);
}
void* valloc(std::size_t size) noexcept {
  count_allocation();
  return __libc_valloc(size);
}
void* pvalloc(std::size_t size) noexcept {
  count_allocation();
  return __libc_pvalloc(size);
}
void free(void* p) noexcept {
  __libc_free(p);
}
}

// every global operator new, counted once each (they go to glibc directly, not through the
// counted malloc above)
namespace {
void* counted_new(std::size_t size) {
  count_allocation();
  return __libc_malloc(size ? size : 1);
}
void* counted_aligned_new(std::size_t size, std::align_val_t alignment) {
  count_allocation();
  return __libc_memalign(static_cast<std::size_t>(alignment), size ? size : 1);
}
}  // namespace

void* operator new(std::size_t size) {
  if (void* p = counted_new(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = counted_new(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return counted_new(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return counted_new(size);
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (void* p = counted_aligned_new(size, alignment)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  if (void* p = counted_aligned_new(size, alignment)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return counted_aligned_new(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return counted_aligned_new(size, alignment);
}
void operator delete(void* p) noexcept {
  __libc_free(p);
}
void operator delete[](void* p) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  __libc_free(p);
}

namespace depotwin {
namespace {

// the allocations `allocate` makes, by the counter
template <typename Allocate>
long allocations_in(Allocate allocate) {
  const long before = g_allocations.load(std::memory_order_relaxed);
  allocate();
  return g_allocations.load(std::memory_order_relaxed) - before;
}

// The counter sees each way to allocate exactly once: the C functions, every operator new,
// MuJoCo's mju_malloc (posix_memalign inside libmujoco) and a std::vector's growth (inside
// libstdc++'s templates, through operator new). The control for the test below.
TEST(AllocationCounter, CountsEveryWayToAllocate) {
  struct alignas(64) CacheLine {
    double values[8];
  };
  EXPECT_EQ(allocations_in([] {
              void* p = std::malloc(24);
              escape(p);
              std::free(p);
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              void* p = std::calloc(3, 8);
              escape(p);
              std::free(p);
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              void* p = std::realloc(nullptr, 16);
              escape(p);
              p = std::realloc(p, 4096);
              escape(p);
              std::free(p);
            }),
            2);
  EXPECT_EQ(allocations_in([] {
              void* p = nullptr;
              if (posix_memalign(&p, 64, 100) == 0) escape(p);
              std::free(p);
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              void* p = std::aligned_alloc(64, 128);
              escape(p);
              std::free(p);
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              int* p = new int(3);
              escape(p);
              delete p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              int* p = new int[5];
              escape(p);
              delete[] p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              int* p = new (std::nothrow) int(4);
              escape(p);
              delete p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              CacheLine* p = new CacheLine();
              escape(p);
              EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % 64, 0u);
              delete p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              CacheLine* p = new (std::nothrow) CacheLine[2];
              escape(p);
              delete[] p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              void* p = mju_malloc(256);
              escape(p);
              mju_free(p);
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              std::vector<double> v;
              v.push_back(1.0);
              escape(v.data());
            }),
            1);
}

TEST(StepLoop, AllocatesNothingBetweenSteps) {
  const auto machine = make_xy_stage();
  const auto print = testing_util::straight_print(Vec3(0, 0, 0), Vec3(1, 2, 0), 3.0, 2.0,
                                                  MachineLimits::uniform(4, 30));
  Simulation simulation(testing_util::xy_stage_model(), *machine);
  long first = -1, last = -1, calls = 0;
  simulation.run(print.trajectory, [&](const StepState&, const StepState&) {
    const long now = g_allocations.load(std::memory_order_relaxed);
    if (calls == 0) first = now;
    last = now;
    ++calls;
  });
  ASSERT_GT(calls, 500);
  EXPECT_EQ(last - first, 0) << "allocations inside the step loop";
}

}  // namespace
}  // namespace depotwin
