# Which link key the tests build the STM32 image with, in one place: `cargo xtask ci` evaluates
# it and gives its AUV150_LINK_KEY to every later step; source it yourself before building the
# firmware by hand. The STM32 image signs its link and does not build without a key
# (firmware/README.md, "Link key"). Unless the caller gave one (AUV150_LINK_KEY)
# or opted out (AUV150_LINK_UNSIGNED=1), the tests build it with the PUBLIC CI test key,
# firmware/ci-test-link-key.hex: such an ELF says so in its build log and at boot, and must
# never be flown.
if [ -z "${AUV150_LINK_KEY:-}" ] && [ -z "${AUV150_LINK_UNSIGNED:-}" ]; then
    AUV150_LINK_KEY="$(grep -v '^#' "$(dirname "${BASH_SOURCE[0]}")/../firmware/ci-test-link-key.hex")"
    export AUV150_LINK_KEY
fi
