/* Counts the frames rviz draws, for bench/rviz_fps.py: loaded with LD_PRELOAD,
 * it wraps glXSwapBuffers (Ogre's GL render system presents every frame with
 * it) and appends "<CLOCK_MONOTONIC seconds> <frames so far>" to the file
 * named by STC_FPS_LOG after each frame. Built by rviz_fps.py with
 * `cc -shared -fPIC`. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

typedef void (*SwapBuffers)(void* display, unsigned long drawable);

void glXSwapBuffers(void* display, unsigned long drawable) {
  static SwapBuffers next;
  static long frames;
  static int log_fd = -2;
  if (!next) next = (SwapBuffers)dlsym(RTLD_NEXT, "glXSwapBuffers");
  if (next) next(display, drawable);
  ++frames;
  if (log_fd == -2) {
    const char* path = getenv("STC_FPS_LOG");
    log_fd = path ? open(path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644) : -1;
  }
  if (log_fd < 0) return;
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  char line[64];
  const int n = snprintf(line, sizeof line, "%ld.%09ld %ld\n", (long)now.tv_sec, now.tv_nsec, frames);
  if (n > 0 && write(log_fd, line, (size_t)n) < 0) log_fd = -1;
}
