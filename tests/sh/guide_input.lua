-- guide_input.lua -- used by tests/sh/guide.sh (not a test itself): write
-- the ```lua blocks of a Markdown file as input for the prompt, each after a
-- marker line `print("@@block <line>")`; blocks opened with "```lua -- not
-- run" are left out.  Native code is off (the tape: no compiler runs).
local file = assert(arg[1], "usage: guide_input.lua file.md")
local out = {'dm.config.native = "never"'}
local n, inblock = 0, false
for line in io.lines(file) do
  n = n + 1
  if inblock then
    if line:match("^```%s*$") then
      inblock = false
    else
      out[#out + 1] = line
    end
  elseif line:match("^```lua%s*$") then
    inblock = true
    out[#out + 1] = string.format('print("@@block %d")', n)
  end
end
assert(not inblock, file .. ": a ```lua block is not closed")
out[#out + 1] = 'print("@@end")'
io.write(table.concat(out, "\n"), "\n")
