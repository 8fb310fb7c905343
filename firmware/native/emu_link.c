#include "emu_link.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

static int set_nonblocking(int fd)
{
    int flags = fcntl(fd, F_GETFL);
    return flags < 0 ? -1 : fcntl(fd, F_SETFL, flags | O_NONBLOCK);
}

static int open_pty(emu_link *l)
{
    struct termios tio;
    const char *name;
    int master = posix_openpt(O_RDWR | O_NOCTTY);

    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0 || !(name = ptsname(master))) {
        perror("quadstep-emu: pseudo-terminal");
        return 0;
    }
    l->slave_fd = open(name, O_RDWR | O_NOCTTY);
    if (l->slave_fd < 0 || tcgetattr(l->slave_fd, &tio) != 0) {
        perror("quadstep-emu: pseudo-terminal slave");
        return 0;
    }
    /* Raw bytes both ways: no echo, no line editing, no CR/LF changes. */
    cfmakeraw(&tio);
    if (tcsetattr(l->slave_fd, TCSANOW, &tio) != 0 || set_nonblocking(master) != 0) {
        perror("quadstep-emu: pseudo-terminal mode");
        return 0;
    }
    l->fd = master;
    printf("PORT %s\n", name);
    return 1;
}

static int open_tcp(emu_link *l, uint16_t port)
{
    struct sockaddr_in addr;
    socklen_t len = sizeof addr;
    int one = 1;
    int s = socket(AF_INET, SOCK_STREAM, 0);

    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(port);
    if (s < 0 || setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0
        || bind(s, (struct sockaddr *)&addr, sizeof addr) != 0 || listen(s, 1) != 0
        || getsockname(s, (struct sockaddr *)&addr, &len) != 0 || set_nonblocking(s) != 0) {
        fprintf(stderr, "quadstep-emu: cannot listen on 127.0.0.1:%u: %s\n", port, strerror(errno));
        return 0;
    }
    l->listen_fd = s;
    printf("PORT socket://127.0.0.1:%u\n", ntohs(addr.sin_port));
    return 1;
}

int emu_link_open(emu_link *l, const emu_options *o)
{
    int ok;

    l->tcp = o->tcp;
    l->listen_fd = -1;
    l->fd = -1;
    l->slave_fd = -1;
    l->clients = 0;
    ok = o->tcp ? open_tcp(l, o->tcp_port) : open_pty(l);
    fflush(stdout);
    return ok;
}

void emu_link_close(emu_link *l)
{
    if (l->fd >= 0)
        close(l->fd);
    if (l->slave_fd >= 0)
        close(l->slave_fd);
    if (l->listen_fd >= 0)
        close(l->listen_fd);
    l->fd = l->slave_fd = l->listen_fd = -1;
}

int emu_link_poll_setup(const emu_link *l, struct pollfd *p, int want_write)
{
    int n = 0;

    if (l->fd >= 0) {
        p[n].fd = l->fd;
        p[n].events = (short)(POLLIN | (want_write ? POLLOUT : 0));
        p[n].revents = 0;
        n++;
    } else if (l->listen_fd >= 0) {
        p[n].fd = l->listen_fd;
        p[n].events = POLLIN;
        p[n].revents = 0;
        n++;
    }
    return n;
}

int emu_link_accept(emu_link *l, const struct pollfd *p, int n)
{
    int one = 1;
    int fd;

    if (!l->tcp || l->fd >= 0 || n == 0 || !(p[0].revents & POLLIN))
        return 0;
    fd = accept(l->listen_fd, NULL, NULL);
    if (fd < 0)
        return 0;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    set_nonblocking(fd);
    l->fd = fd;
    l->clients++;
    return 1;
}

static void drop_client(emu_link *l)
{
    if (l->tcp && l->fd >= 0) {
        close(l->fd);
        l->fd = -1;
    }
}

size_t emu_link_read(emu_link *l, uint8_t *buf, size_t cap)
{
    ssize_t got;

    if (l->fd < 0)
        return 0;
    got = read(l->fd, buf, cap);
    if (got > 0)
        return (size_t)got;
    if (got == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR))
        drop_client(l); /* the TCP client hung up; a pty master never does */
    return 0;
}

size_t emu_link_write(emu_link *l, const uint8_t *buf, size_t len)
{
    ssize_t put;

    if (l->fd < 0 || len == 0)
        return 0;
    put = write(l->fd, buf, len);
    if (put > 0)
        return (size_t)put;
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
        drop_client(l);
    return 0;
}
