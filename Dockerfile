# vc-server image: build and test on Debian 12, then a slim runtime with a non-root user.
# Base from a build argument so the same file builds from the public image and, on machines without
# a registry, from a locally imported one (docs/DEPLOY.md, scripts/container-test.sh):
#   podman build --build-arg BASE=localhost/debian:bookworm -t vc:dev .
ARG BASE=debian:bookworm

FROM ${BASE} AS build
# Packages: scripts/install-deps.sh's lists (build: ... coinor-libcbc-dev, libjs-three; runtime: ...
# coinor-libcbc3; report.html carries three.js inside the binary, so the runtime needs neither).
WORKDIR /src
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN bash scripts/install-deps.sh && rm -rf /var/lib/apt/lists/*
COPY . .
# Tests that need ../shared/data skip themselves when it is absent; VC_SKIP_TESTS=1 skips them all.
ARG VC_SKIP_TESTS=0
RUN rm -rf build && cmake --preset release -DVC_BUILD_BENCH=OFF \
 && cmake --build --preset release \
 && if [ "$VC_SKIP_TESTS" != 1 ]; then ctest --preset release -j2 -L 'server|tsan'; fi \
 && install -D build/release/server/vc-server /out/usr/local/bin/vc-server \
 && install -D build/release/client/vc-client /out/usr/local/bin/vc-client

FROM ${BASE} AS runtime
COPY scripts/install-deps.sh /tmp/install-deps.sh
RUN bash /tmp/install-deps.sh --runtime && rm -rf /var/lib/apt/lists/* /tmp/install-deps.sh \
 && useradd --system --uid 10001 --no-create-home --shell /usr/sbin/nologin vc
COPY --from=build /out/ /
USER 10001
ENV VC_LISTEN=0.0.0.0:50051
EXPOSE 50051
HEALTHCHECK --interval=15s --timeout=5s --start-period=5s --retries=3 \
  CMD ["vc-client", "health", "--server", "127.0.0.1:50051", "--retries", "1", "--timeout", "4"]
ENTRYPOINT ["vc-server"]
