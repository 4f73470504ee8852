-- fuzz case: dm.lie.group(0/0): cannot read '-nan'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.lie.group"](H["nan"])
end
