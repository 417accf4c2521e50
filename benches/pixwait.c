/* pixwait X Y CHANNEL T0_MS TIMEOUT_MS: polls the root window's pixel (X, Y)
 * every 3 ms until CHANNEL (0 red, 1 green) is above 150 and the other below
 * 40, then prints the milliseconds since T0_MS (wall clock, as `date +%s%3N`
 * gives) and exits 0; prints "timeout" and exits 1 after TIMEOUT_MS. One
 * pixel by XGetImage costs well under a millisecond, so the observer adds
 * little to what it measures (a full-screen grab per sample adds 0.1-0.4 s
 * on a loaded 2-core machine). Used by reload.sh. */
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

static long now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return t.tv_sec * 1000L + t.tv_nsec / 1000000;
}

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: pixwait X Y CHANNEL T0_MS TIMEOUT_MS\n");
        return 2;
    }
    Display *d = XOpenDisplay(NULL);
    if (!d) {
        fprintf(stderr, "pixwait: cannot open the display\n");
        return 2;
    }
    int x = atoi(argv[1]), y = atoi(argv[2]), want = atoi(argv[3]);
    long t0 = atol(argv[4]), limit = atol(argv[5]);
    Window root = DefaultRootWindow(d);
    for (;;) {
        XImage *im = XGetImage(d, root, x, y, 1, 1, AllPlanes, ZPixmap);
        if (im) {
            unsigned long p = XGetPixel(im, 0, 0);
            XDestroyImage(im);
            int r = (p >> 16) & 255, g = (p >> 8) & 255;
            int on = want ? g : r, off = want ? r : g;
            if (on > 150 && off < 40) {
                printf("%ld\n", now_ms() - t0);
                return 0;
            }
        }
        if (now_ms() - t0 > limit) {
            printf("timeout\n");
            return 1;
        }
        usleep(3000);
    }
}
