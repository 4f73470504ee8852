# file_targets.sh -- tr:save and dm.plot{output = ...} never replace what
# is not a regular file: a symbolic link is followed (the link stays), a
# FIFO or character device is written through, a directory or socket is
# refused; long names and NUL bytes in names.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/file_targets"; rm -rf "$T"; mkdir -p "$T"
have_png=$("$D" -e 'local ok, t = pcall(dm._gp.terminals); print(ok and t:find("png") ~= nil)' 2>/dev/null)

cat > "$T/save.lua" <<'LUA'
local tr = dm.trajectory{t = {0, 0.5, 1}, coords = {'x'}, q = {x = {2.385, 1, 0}}}
local ok, msg = tr:save(arg[1]); print(ok or msg)
LUA
cat > "$T/plot.lua" <<'LUA'
local ok, msg = pcall(dm.plot, { {{0, 1, 2}, {2.385, 1, 0}}, output = arg[1],
                                 terminal = not arg[1]:find("%.png$") and "png" or nil })
print(ok or msg)
LUA
save() { "$D" "$T/save.lua" "$1" 2>&1; }  # a 3-sample trajectory: "true" or the message
plot() { "$D" "$T/plot.lua" "$1" 2>&1; }  # a small PNG: "true" or the message

# a symbolic link to a regular file: followed, the link stays a link
echo old > "$T/real.csv"; ln -s real.csv "$T/link.csv"
out=$(save "$T/link.csv"); is "$out" "true" "save through a symlink"
test -L "$T/link.csv"; ok $? "the symlink is still a symlink"
grep -q '^0.5,1$' "$T/real.csv"; ok $? "the file it points to holds the trajectory"
ln -s nowhere.csv "$T/dangling.csv"
out=$(save "$T/dangling.csv")
like "$out" "saving '.*dangling.csv': the symbolic link points to nothing" "a dangling symlink is refused"
test -L "$T/dangling.csv" && ! test -e "$T/nowhere.csv"; ok $? "... and stays a dangling symlink"

# a FIFO with a reader: written through; the FIFO stays a FIFO
mkfifo "$T/fifo"
timeout 20 cat "$T/fifo" > "$T/fifo.out" & reader=$!
out=$(save "$T/fifo"); is "$out" "true" "save into a FIFO with a reader"
wait $reader
test -p "$T/fifo"; ok $? "the FIFO is still a FIFO"
grep -q '^0.5,1$' "$T/fifo.out"; ok $? "the reader got the trajectory"
out=$(DMECH_FIFO_TIMEOUT=0.2 save "$T/fifo")
like "$out" "saving '.*fifo': nobody reads this FIFO \(waited 0.2 s\)" "a FIFO nobody reads: clear message"
test -p "$T/fifo"; ok $? "... and the FIFO is still a FIFO"

# directories and sockets are refused
mkdir "$T/dir"
out=$(save "$T/dir"); like "$out" "saving '.*dir': is a directory, not a file" "a directory is refused"
test -d "$T/dir"; ok $? "... and stays a directory"
out=$(save "$T/dir/"); like "$out" "saving '.*dir/': is a directory name" "a name ending in / is refused"
if command -v python3 >/dev/null 2>&1; then
  python3 -c "import socket,sys; s=socket.socket(socket.AF_UNIX); s.bind(sys.argv[1])" "$T/sock"
  out=$(save "$T/sock"); like "$out" "saving '.*sock': is a socket, not a file" "a socket is refused"
  test -S "$T/sock"; ok $? "... and stays a socket"
else
  skip "python3 not installed (socket)"; skip "python3 not installed (socket)"
fi

# character devices: our own nodes (as root) for /dev/null and /dev/full
if [ "$(id -u)" = 0 ] && mknod "$T/null" c 1 3 2>/dev/null && mknod "$T/full" c 1 7 2>/dev/null; then
  out=$(save "$T/null"); is "$out" "true" "save to a null device"
  test -c "$T/null"; ok $? "the device is still a device"
  out=$(save "$T/full")
  like "$out" "(saving|writing) '.*full': No space left on device" "save to a full device: ENOSPC reported"
  test -c "$T/full"; ok $? "the full device is still a device"
  if [ "$have_png" = true ]; then
    out=$(plot "$T/null"); is "$out" "true" "plot to a null device"
    test -c "$T/null"; ok $? "... still a device"
    out=$(plot "$T/full"); like "$out" "plot output '.*full': No space left on device" "plot to a full device: ENOSPC"
    test -c "$T/full"; ok $? "... still a device"
  else
    for i in 1 2 3 4; do skip "gnuplot without png"; done
  fi
else
  # not root: the real /dev/full (as root a regression would replace it)
  out=$(save /dev/full); like "$out" "(saving|writing) '/dev/full': No space left on device" "save to /dev/full: ENOSPC"
  test -c /dev/full; ok $? "/dev/full is still a character device"
  for i in 1 2 3 4 5 6; do skip "not root: cannot create device nodes"; done
fi

if [ "$have_png" = true ]; then
  # plots: through a symlink, into a FIFO, refused for a directory
  echo old > "$T/real.png"; ln -s real.png "$T/link.png"
  out=$(plot "$T/link.png"); is "$out" "true" "plot through a symlink"
  test -L "$T/link.png" && [ "$(head -c 4 "$T/real.png" | od -An -c | tr -d ' ')" = "211PNG" ]
  ok $? "the link stays, the file it points to is a PNG"
  mkfifo "$T/plotfifo"
  timeout 20 cat "$T/plotfifo" > "$T/plotfifo.out" & reader=$!
  out=$(plot "$T/plotfifo"); is "$out" "true" "plot into a FIFO with a reader"
  wait $reader
  test -p "$T/plotfifo" && [ "$(head -c 4 "$T/plotfifo.out" | od -An -c | tr -d ' ')" = "211PNG" ]
  ok $? "the FIFO stays, the reader got a PNG"
  out=$(plot "$T/dir.png/"); like "$out" "output file name '.*dir.png/' is a directory" "plot to a directory name refused"
  mkdir "$T/d.png"; out=$(plot "$T/d.png"); like "$out" "plot output '.*d.png': is a directory, not a file" "plot to a directory refused"
else
  for i in 1 2 3 4 5 6; do skip "gnuplot without png"; done
fi

# a name as long as the file system allows: the temporary name fits too
long=$(printf 'a%.0s' $(seq 1 250)).csv
out=$(save "$T/$long"); is "$out" "true" "save to a 254-byte file name"
grep -q '^0.5,1$' "$T/$long"; ok $? "... written"
long=$(printf '\303\251%.0s' $(seq 1 124)).csv       # 124 x 'é' (2 bytes each)
out=$(save "$T/$long"); is "$out" "true" "save to a 252-byte UTF-8 file name"
left=$(ls -a "$T" | grep -c '\.tmp$'); is "$left" 0 "no temporary file left behind"

# NUL bytes in names and metadata are refused, never truncated
cat > "$T/nul.lua" <<'LUA'
local tr = dm.trajectory{t = {0}, coords = {'x'}, q = {x = {1}}}
print(pcall(tr.save, tr, arg[1] .. '/nul\0.csv'))
LUA
out=$("$D" "$T/nul.lua" "$T" 2>&1)
like "$out" "false.*bad argument #2 to 'trajectory:save' \(string without NUL bytes expected, got a string with a NUL byte at position" "NUL in a save path"
test -e "$T/nul"; is $? 1 "... and nothing written at the truncated name"
out=$("$D" -e "print(pcall(dm.load_trajectory, 'x\0y'))" 2>&1)
like "$out" "false.*bad argument #1 to 'dmech.load_trajectory' \(string without NUL bytes" "NUL in a load path"
out=$("$D" -e "print(pcall(dm.trajectory, {t = {0}, coords = {'x'}, q = {x = {1}}, meta = {note = 'a\0b'}}))" 2>&1)
like "$out" "false.*metadata value: NUL byte at position 2" "NUL in a metadata value"
out=$("$D" -e "local tr = dm.trajectory{t = {0}, coords = {'x'}, q = {x = {1}}}
               print(pcall(tr.meta, tr, 'k\0ey', 'v'))" 2>&1)
like "$out" "false.*bad argument #2 to 'trajectory:meta' \(string without NUL bytes" "NUL in a metadata key"
out=$("$D" -e "print(pcall(dm.plot, { {{0, 1}, {1, 2}}, output = 'a\0.png' }))" 2>&1)
like "$out" "false.*output: file name without NUL bytes expected, got a NUL byte at position 2" "NUL in a plot file name"
done_testing
