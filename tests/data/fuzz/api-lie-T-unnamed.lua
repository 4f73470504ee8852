-- fuzz case: pcall(dm.lie.T, f) named the function '?'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.lie.T"](H["f_noop"])
end
