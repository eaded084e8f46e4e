/* SPDX-License-Identifier: MIT
 * What loading Embree costs a process, whatever the program around it does
 * (docs/performance.md, "Start-up"). Built three ways and timed whole, e.g. with
 * `perf stat -r 30 ./PROGRAM`:
 *
 *   cc -O2 bench/load_floor.c -o floor_none                                 # nothing linked
 *   cc -O2 bench/load_floor.c -o floor_tbb -Wl,--no-as-needed -ltbb -lstdc++
 *   cc -O2 -DWITH_EMBREE bench/load_floor.c -o floor_embree -Wl,--no-as-needed -lembree3
 *
 * `floor_embree` alone loads Embree and calls nothing; `floor_embree threads=2` also makes a
 * device with that configuration and commits an empty scene.
 */
#ifdef WITH_EMBREE
#include <embree3/rtcore.h>
#endif

int main(int argc, char** argv) {
#ifdef WITH_EMBREE
    if (argc > 1) {
        RTCDevice device = rtcNewDevice(argv[1]);
        RTCScene scene = rtcNewScene(device);
        rtcCommitScene(scene);
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
#else
    (void)argc;
    (void)argv;
#endif
    return 0;
}
