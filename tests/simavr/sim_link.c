/* The host's end of the serial line (see sim_link.h). */
#define _XOPEN_SOURCE 600
#define _DEFAULT_SOURCE

#include "sim_link.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#define OUT_CAP (1u << 20)

struct sim_link {
    int in_fd;
    int out_fd;
    int keep_fd; /* the pty's slave end, held open so a host can reconnect */
    uint8_t *out;
    size_t out_len;
};

static sim_link *link_new(int in_fd, int out_fd)
{
    sim_link *l = calloc(1, sizeof *l);
    if (!l) {
        return NULL;
    }
    l->out = malloc(OUT_CAP);
    if (!l->out) {
        free(l);
        return NULL;
    }
    l->in_fd = in_fd;
    l->out_fd = out_fd;
    l->keep_fd = -1;
    fcntl(in_fd, F_SETFL, fcntl(in_fd, F_GETFL) | O_NONBLOCK);
    fcntl(out_fd, F_SETFL, fcntl(out_fd, F_GETFL) | O_NONBLOCK);
    return l;
}

sim_link *sim_link_open_pty(void)
{
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
        perror("pseudo-terminal");
        return NULL;
    }
    const char *name = ptsname(master);
    const int slave = name ? open(name, O_RDWR | O_NOCTTY) : -1;
    struct termios tio;
    if (slave < 0 || tcgetattr(slave, &tio) != 0) {
        perror("pseudo-terminal slave");
        return NULL;
    }
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    sim_link *l = link_new(master, master);
    if (!l) {
        return NULL;
    }
    l->keep_fd = slave;
    printf("PORT %s\n", name);
    fflush(stdout);
    return l;
}

sim_link *sim_link_open_stdio(void)
{
    return link_new(STDIN_FILENO, STDOUT_FILENO);
}

size_t sim_link_read(sim_link *l, uint8_t *buf, size_t cap, int *eof)
{
    const ssize_t got = read(l->in_fd, buf, cap);
    if (got > 0) {
        return (size_t)got;
    }
    if (got == 0 && l->keep_fd < 0) {
        *eof = 1; /* stdin ended; a pty never ends while we hold its slave */
    }
    return 0;
}

void sim_link_put(sim_link *l, uint8_t byte)
{
    if (l->out_len == OUT_CAP) {
        sim_link_flush(l);
        if (l->out_len == OUT_CAP) {
            /* The host has not read a megabyte: like a board whose USB
             * bridge buffer is full, the oldest byte goes. */
            memmove(l->out, l->out + 1, OUT_CAP - 1);
            l->out_len--;
        }
    }
    l->out[l->out_len++] = byte;
}

void sim_link_flush(sim_link *l)
{
    size_t done = 0;
    while (done < l->out_len) {
        const ssize_t n = write(l->out_fd, l->out + done, l->out_len - done);
        if (n <= 0) {
            break; /* EAGAIN, or no reader: try again later */
        }
        done += (size_t)n;
    }
    memmove(l->out, l->out + done, l->out_len - done);
    l->out_len -= done;
}
