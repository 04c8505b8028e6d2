/*
 * Linked into the C tests built against a libmpca compiled with
 * ThreadSanitizer by nightly Rust (MPCA_C_SANITIZE=thread): its LLVM
 * instruments the library's copies and fills as calls of __tsan_memcpy,
 * __tsan_memset and __tsan_memmove, which GCC's libtsan does not define
 * (newer LLVM runtimes do). These forward them to the C library's
 * functions, which libtsan intercepts, so each range is still checked as
 * the access it is. Weak, so that a runtime defining them wins.
 */
#include <string.h>

void *__tsan_memcpy(void *to, const void *from, size_t n);
void *__tsan_memset(void *to, int c, size_t n);
void *__tsan_memmove(void *to, const void *from, size_t n);

__attribute__((weak)) void *__tsan_memcpy(void *to, const void *from, size_t n) {
    return memcpy(to, from, n);
}

__attribute__((weak)) void *__tsan_memset(void *to, int c, size_t n) {
    return memset(to, c, n);
}

__attribute__((weak)) void *__tsan_memmove(void *to, const void *from, size_t n) {
    return memmove(to, from, n);
}
