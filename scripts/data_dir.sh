# Sourced by the benchmark scripts: sets `data` to the scans directory, the script's first argument
# if given, else ../shared/data beside the repository, else /work/shared/data.
data="${1:-}"
if [ -z "$data" ]; then
  if [ -d ../shared/data ]; then data=../shared/data; else data=/work/shared/data; fi
fi
