# shellcheck shell=sh
# Sourced by the bench scripts that read bench/md2csv.awk's CSV files.
# csv_fields FILE...: the rows as tab-separated lines (quotes respected).
csv_fields() {
    awk '{ out = ""; q = 0
           for (i = 1; i <= length($0); i++) {
               c = substr($0, i, 1)
               if (c == "\"") q = !q
               else if (c == "," && !q) out = out "\t"
               else out = out c
           }
           print out }' "$@"
}
