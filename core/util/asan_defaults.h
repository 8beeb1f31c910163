// AddressSanitizer's defaults for pt's executables (included once by each file holding a main():
// renderer/commands/main.cpp and tests/test_main.cpp); nothing in other builds.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
// new_delete_type_mismatch=0: OpenImageIO 2.4's TextureSystem::destroy() deletes its
// implementation through a base pointer whose sized delete says 1 byte (a 184-byte object); the
// mismatch is inside the library, which pt cannot change, and every scene with a texture cache
// ends there. intercept_tls_get_addr=0: see tests/test_fuzz_scenes.cpp (GCC 12's runtime and
// glibc's dynamic TLS). Both can still be overridden by ASAN_OPTIONS.
extern "C" const char* __asan_default_options() { return "new_delete_type_mismatch=0:intercept_tls_get_addr=0"; }
#endif
