" qcs scene scripts (editors/vim/syntax/qcs.vim)
autocmd BufRead,BufNewFile *.qcs setfiletype qcs
