// No tests here: the sanitizer build's leak check is turned off for this
// binary only. Mesa's OSMesa (OSMesaMakeCurrent's framebuffer state) and
// llvmpipe's JIT-compiled shaders allocate per-context memory they never
// free, in frames without symbols (JIT code), so no suppression pattern can
// name them; AddressSanitizer's memory-error checks stay on.
extern "C" int __lsan_is_turned_off() { return 1; }
