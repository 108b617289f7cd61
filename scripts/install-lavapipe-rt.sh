#!/usr/bin/env bash
# Installs lavapipe with ray tracing (Mesa 25 from Debian's bookworm-backports) into a project-local
# folder, without touching the system's Vulkan drivers.
#
#   scripts/install-lavapipe-rt.sh [DIR]      (default DIR: <repo>/.deps/lavapipe-rt)
#
# Debian 12's own lavapipe (Mesa 22.3) has no ray tracing. Backports' mesa-vulkan-drivers 25 has
# VK_KHR_acceleration_structure, VK_KHR_ray_query and VK_KHR_ray_tracing_pipeline on the CPU, but
# that package holds every Mesa Vulkan driver: installing it would replace a workstation's RADV or
# ANV too. So this script only downloads it (and the libdrm it needs) through a private apt
# configuration, as any user, and unpacks it with dpkg -x. It writes into DIR:
#   lvp_icd.json   the driver's manifest, with an absolute library_path;
#   lib/           libvulkan_lvp.so and its libdrm;
#   env.sh         `source DIR/env.sh` points one shell's programs at this driver.
# The tests labelled hw run on it (CMake's CROSSRT_TEST_VULKAN_ICD, by default the default DIR's
# lvp_icd.json; see docs/ray-tracing.md).
# Does nothing when DIR already holds it. Needs network access and apt (Debian 12).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;; esac
dir=$(realpath -m "${1:-$root/.deps/lavapipe-rt}")

if [ -f "$dir/lvp_icd.json" ] && [ -f "$dir/lib/libvulkan_lvp.so" ]; then
  echo "install-lavapipe-rt: present in $dir"
  exit 0
fi
command -v apt-get > /dev/null || { echo "install-lavapipe-rt: error: needs apt-get (Debian 12)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lists/partial" "$work/cache/archives/partial" "$work/debs" "$work/root"
keyring=/usr/share/keyrings/debian-archive-keyring.gpg
signed=""; [ -f "$keyring" ] && signed="[signed-by=$keyring] "
echo "deb ${signed}http://deb.debian.org/debian bookworm-backports main" > "$work/sources.list"
apt_options=(-o "Dir::Etc::SourceList=$work/sources.list" -o Dir::Etc::SourceParts=/dev/null
             -o "Dir::State::Lists=$work/lists" -o "Dir::Cache=$work/cache" -o Debug::NoLocking=1
             -o APT::Sandbox::User="$(id -un)")
echo "install-lavapipe-rt: fetching mesa-vulkan-drivers from bookworm-backports into $dir"
apt-get "${apt_options[@]}" -qq update
(cd "$work/debs" && apt-get "${apt_options[@]}" -qq download mesa-vulkan-drivers libdrm2 libdrm-amdgpu1)
for deb in "$work"/debs/*.deb; do dpkg -x "$deb" "$work/root"; done

lib="$work/root/usr/lib/x86_64-linux-gnu"
[ -f "$lib/libvulkan_lvp.so" ] || { echo "install-lavapipe-rt: error: no libvulkan_lvp.so in the package" >&2; exit 1; }
mkdir -p "$dir/lib"
cp -a "$lib"/libvulkan_lvp.so "$lib"/libdrm.so.2* "$lib"/libdrm_amdgpu.so.1* "$dir/lib/"
version=$(sed -n 's/.*"api_version": *"\([^"]*\)".*/\1/p' "$work/root/usr/share/vulkan/icd.d/lvp_icd.json")
cat > "$dir/lvp_icd.json" <<EOF
{
    "ICD": {
        "api_version": "${version:-1.4.305}",
        "library_path": "$dir/lib/libvulkan_lvp.so"
    },
    "file_format_version": "1.0.0"
}
EOF
cat > "$dir/env.sh" <<EOF
# Points this shell's Vulkan programs at lavapipe with ray tracing (Mesa 25), installed by
# scripts/install-lavapipe-rt.sh. Other shells keep the system's drivers.
export VK_ICD_FILENAMES="$dir/lvp_icd.json"
export LD_LIBRARY_PATH="$dir/lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
EOF
echo "install-lavapipe-rt: installed lavapipe $(ls "$work"/debs | sed -n 's/^mesa-vulkan-drivers_\([^_]*\)_.*/\1/p') in $dir"
